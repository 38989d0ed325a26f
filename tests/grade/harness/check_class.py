#!/usr/bin/env python3
"""check_class.py CLOTHLAB SOURCE WORK_DIR: `clothlab grade --class` on two small classes.

A folder per student: a solution of lesson 02, a copy of it (the similarity report must pair the
two, their matching regions on a page of the pair's own that index.html links), a planted mistake
(what-went-wrong must name its failing case and hint), a file that does not compile, and students
whose folder names are hostile (quotes and a `$(...)`, a line break and a fake total, HTML, a
leading dash, 200 characters) and who hand in the shipped stub unchanged (the stub is left out of
the comparison, so no two of them are paired). Then the class again (nothing is graded again), one
file changed (that submission alone is graded again), the class without sim_c++ (graded all the
same, and the report says how to get it), the class interrupted once a changed submission is graded
(the rest is graded by the next run), and Gradescope's export layout, whose metadata names a student
"../../escape". Lesson 02 alone is graded: 26 to 45 s on two shared cores.
"""
import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys

clothlab, source, work = sys.argv[1:4]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
problems = []


def problem(text):
    problems.append(text)
    print("PROBLEM:", text)


EX = "02_spring_dampers.cpp"
solution = open(os.path.join(source, "solutions", EX)).read()
stub = open(os.path.join(source, "exercises", EX)).read()
# The planted mistake of tests/grade/harness/planted/mutants.txt for ex02.2: the energy without
# its 1/2.
planted = solution.replace("return 0.5 * ks * stretch * stretch;", "return 1.0 * ks * stretch * stretch;")
assert planted != solution, "the planted line is no longer in solutions/" + EX

klass = os.path.join(work, "class")
hostile = {
    "quote'\"$(touch pwned)`touch pwned2`": stub,
    "line\nTotal: 999 of 999 points": stub,
    "<script>alert(1)<\\script>": stub,
    "-rf": None,
    "x" * 200: stub,
}
students = {"alice": solution, "alice-copy": solution, "bob": "int broken(\n" + solution,
            "dave": planted}
students.update(hostile)
for name, text in students.items():
    os.makedirs(os.path.join(klass, name))
    if text is not None:
        with open(os.path.join(klass, name, EX), "w") as f:
            f.write(text)
out = os.path.join(work, "report")


def grade(class_dir, out_dir, env=None):
    run = subprocess.run([clothlab, "grade", "--class", class_dir, "--out", out_dir, "--exercise",
                          "ex02", "--jobs", "2"], cwd=work, env=env, stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True, errors="replace")
    print(run.stdout)
    if run.returncode != 0:
        problem(f"grade --class {class_dir} exited with {run.returncode}")
    return run.stdout


def table(out_dir):
    with open(os.path.join(out_dir, "class.csv"), newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], {row[0]: row for row in rows[1:]}


before = set(os.listdir(work))
said = grade(klass, out)
header, rows = table(out)
total = [i for i, h in enumerate(header) if h.startswith("total")][0]
status = header.index("status")
max_points = int(re.search(r"\((\d+) points\)", header[total]).group(1))
if len(rows) != len(students):
    problem(f"class.csv has {len(rows)} students, expected {len(students)}")
if rows.get("alice", [None] * 99)[total] != str(max_points):
    problem(f"alice (the solution) is not at full marks: {rows.get('alice')}")
if "not compiled" not in rows.get("bob", [""] * 99)[status]:
    problem(f"bob's file does not compile, and his status says {rows.get('bob')}")
dave = int(rows.get("dave", ["0"] * 99)[total] or 0)
if not 0 < dave < max_points:
    problem(f"dave's planted mistake should lose some points, not all: {rows.get('dave')}")
# Every name is one line of the table, escaped; none reached a shell or a path.
for name in hostile:
    shown = name.replace("\n", "\\n")
    shown = "'" + shown if shown[0] in "=+-@" else shown
    if shown not in rows:
        problem(f"the student {name!r} is not in class.csv as {shown!r}")
for path in ("pwned", "pwned2", os.path.join(klass, "pwned")):
    if os.path.exists(os.path.join(work, path)):
        problem(f"a folder name ran a command: {path} exists")
if set(os.listdir(work)) - before - {"report"}:
    problem(f"grading wrote outside the report folder: {set(os.listdir(work)) - before}")
files = os.listdir(os.path.join(out, "submissions"))
if len(files) != len(students) or not all(re.fullmatch(r"[A-Za-z0-9_-]+\.json", f) for f in files):
    problem(f"submissions/ should hold a JSON of a plain name per student: {files}")
for f in files:
    record = json.load(open(os.path.join(out, "submissions", f)))
    if record["student"] not in students or "cases" not in record:
        problem(f"{f}: not a submission's record")
page = open(os.path.join(out, "index.html")).read()
if "<script>" in page or "&lt;script&gt;alert(1)&lt;\\script&gt;" not in page:
    problem("index.html does not show the name <script>... escaped")
if "Total: 999" in "\n".join(l for l in page.splitlines() if l.startswith("Total")):
    problem("a name drew a line of its own in index.html")
# What the class got wrong: dave's case, with its hint and his failing output, anonymised.
wrong = open(os.path.join(out, "what-went-wrong.txt")).read()
print(wrong)
if not re.search(r"ex02\.2 \S.* failed by 1\n    1 x hint: .+\n    for example:\n", wrong):
    problem("what-went-wrong.txt does not list ex02.2's failing case with a hint and an example")
if "56 J means the 1/2 is missing" not in wrong or "\n      tests/grade/02_spring_dampers.cpp:" not in wrong:
    problem("what-went-wrong.txt does not name dave's mistake, or shows the grading file oddly")
if "dave" in wrong:
    problem("what-went-wrong.txt names a student")
# Similarity: alice and her copy, at 100 %; the students who handed in the stub are not compared.
similar = open(os.path.join(out, "similarity.txt")).read()
print(similar)
pairs = [l for l in similar.splitlines() if " % of " in l]
if not any(re.search(r"(9\d|100) % of alice(-copy)? is in alice(-copy)?;", l) for l in pairs):
    problem("similarity.txt does not pair alice and her copy at 90 % or more")
if any("script" in l or "xxxx" in l or "quote" in l for l in pairs):
    problem("students who handed in the shipped stub are paired: the stub was compared")
if "ex02.2" not in page or "alice" not in page.split("Similar code")[1]:
    problem("index.html lacks what went wrong or the similar pair")
# The matching regions are on a page of each pair's own (pairs/pair-NN.html), linked from its row
# of index.html: side by side, each line as written with its file and line, the lines the students
# share with the shipped stub folded. On index.html itself they made the page of a class of 50
# megabytes long, so it holds none of the students' code.
if 'class="side"' in page or "f_sd" in page:
    problem("index.html holds matching regions itself: they belong on each pair's page")
rows_linked = re.findall(r'<tr><td>(\d+)</td>.*?<a href="pairs/(pair-\d\d\.html)">', page)
if not rows_linked or [int(n) for n, _ in rows_linked] != list(range(1, len(rows_linked) + 1)):
    problem(f"index.html's similar pairs are not ranked rows linking their pages: {rows_linked}")
alice_row = [l for l in page.splitlines() if re.search(r">alice(-copy)?</td><td class=\"l\">alice(-copy)?<", l)]
link = re.search(r'href="pairs/(pair-\d\d\.html)"', alice_row[0]) if alice_row else None
pair_page = os.path.join(out, "pairs", link.group(1)) if link else ""
if not os.path.isfile(pair_page):
    problem(f"the pair alice and alice-copy has no page of its own: {alice_row}")
else:
    side = open(pair_page).read()
    if not re.search(r'<tr><td><pre>02:\d+ +\S', side) or "const double f_sd = -ks * (l0 - l)" not in side:
        problem(f"{pair_page} does not show alice's lines side by side with their places")
    if "Exercise ex02.2: the energy" in side or "lines as in the shipped stub" not in side:
        problem(f"{pair_page} shows the lines of the shipped stub between the exercises unfolded")
pairs_dir = os.path.join(out, "pairs")
if sorted(os.listdir(pairs_dir) if os.path.isdir(pairs_dir) else []) != sorted(l for _, l in rows_linked):
    problem("pairs/ holds other pages than those index.html links")

# Again: nothing to grade. Then bob mends his file: he alone is graded again.
said = grade(klass, out)
if f"0 to grade, {len(students)} graded before" not in said:
    problem("the class graded again with no file changed is graded again")
with open(os.path.join(klass, "bob", EX), "w") as f:
    f.write(solution)
said = grade(klass, out)
if f"1 to grade, {len(students) - 1} graded before" not in said:
    problem("with bob's file changed, not bob alone was graded again")
if table(out)[1].get("bob", [""] * 99)[total] != str(max_points):
    problem("bob's mended file is not at full marks")

# Interrupted (Ctrl-C reaches the whole group) once one of three changed submissions is graded:
# it says so, keeps what was graded, and the same command grades the rest alone.
for name in ("alice", "alice-copy", "dave"):
    with open(os.path.join(klass, name, EX), "a") as f:
        f.write("// handed in again\n")
run = subprocess.Popen([clothlab, "grade", "--class", klass, "--out", out, "--exercise", "ex02",
                        "--jobs", "2"], cwd=work, stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, text=True, start_new_session=True)
said = ""
for line in run.stdout:
    said += line
    if line.startswith("["):
        os.killpg(run.pid, signal.SIGINT)
        break
said += run.stdout.read()
print(said)
if run.wait() != 130 or "interrupted: the submissions graded so far are kept" not in said:
    problem(f"an interrupted class should exit with 130 and say so, not {run.returncode}")
said = grade(klass, out)
left = re.search(r"(\d+) to grade", said)
if not left or not 1 <= int(left.group(1)) <= 2:
    problem("after the interruption, not just the submissions left were graded")

# Without sim_c++, the class is graded and the report says how to get it.
bin_dir = os.path.join(work, "bin")
os.makedirs(bin_dir)
for d in os.environ.get("PATH", "/usr/bin:/bin").split(":"):
    if os.path.isdir(d):
        for p in os.listdir(d):
            if not p.startswith("sim_") and not os.path.exists(os.path.join(bin_dir, p)):
                os.symlink(os.path.join(d, p), os.path.join(bin_dir, p))
said = grade(klass, out, dict(os.environ, PATH=bin_dir))
if "apt-get install similarity-tester" not in open(os.path.join(out, "similarity.txt")).read():
    problem("without sim_c++, similarity.txt does not say how to get it")
if os.path.exists(pairs_dir):
    problem("without sim_c++, the pairs' pages of the run before are left in pairs/")
if len(table(out)[1]) != len(students):
    problem("without sim_c++, the class table is not complete")

# Gradescope's export: names from submission_metadata.yml, one of them a path.
export = os.path.join(work, "gradescope", "assignment_7_export")
os.makedirs(os.path.join(export, "submission_111"))
os.makedirs(os.path.join(export, "submission_222"))
with open(os.path.join(export, "submission_111", EX), "w") as f:
    f.write(solution)
with open(os.path.join(export, "submission_metadata.yml"), "w") as f:
    f.write("submission_111:\n  :submitters:\n  - :name: \"../../escape\"\n    :sid: '1'\n"
            "  :score: 0.0\nsubmission_222:\n  :submitters:\n  - :name: Zoe O'Brien\n"
            "    :sid: '2'\n  - :name: Ann Lee\n    :sid: '3'\n")
gs_out = os.path.join(work, "gs-report")
grade(os.path.join(work, "gradescope"), gs_out)
header, rows = table(gs_out)
if set(rows) != {"../../escape", "Zoe O'Brien, Ann Lee"}:
    problem(f"the Gradescope export's students are {set(rows)}")
if rows.get("../../escape", [""] * 99)[total] != str(max_points):
    problem("submission_111 (the solution) is not at full marks")
for root, dirs, names in os.walk(os.path.dirname(work)):
    if root.startswith(bin_dir):
        continue
    # "escape" itself, or "escape." and a suffix: what the name would make as a path (another
    # test's work beside this one may hold names such as "escapes").
    if any(n == "escape" or n.startswith("escape.") for n in names + dirs):
        problem(f"a file named after ../../escape was written in {root}")

if problems:
    print("check_class: " + str(len(problems)) + " problems:\n  " + "\n  ".join(problems))
    sys.exit(1)
print("check_class: the class is graded, resumed, reported and compared as it must be")
