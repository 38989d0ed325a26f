#!/usr/bin/env python3
"""check_gradescope_bundle.py: the Gradescope autograder as Gradescope meets it, in seconds.

    check_gradescope_bundle.py CMAKE CLOTHLAB STUBGEN SOURCE WORK_DIR

Exports the bundle (export_release.cmake, GRADESCOPE=ON) and checks:
  - the zip holds setup.sh and run_autograder at its top, both executable and both parsed by bash,
    and the release in clothlab/: the hidden tests in, no solutions/ and no planted mistakes,
    exercises/ the shipped stubs;
  - setup.sh installs every Debian package the top CMakeLists.txt requires (the package a
    missing dependency's message names), so that `cmake -S . -B build` configures in a fresh image;
  - run_autograder, on this build's grader, grades a submission with lesson 01 solved and lesson
    02's file broken: ex01 full marks, ex02 nothing, reported as not compiled with the compiler's
    error, every other exercise its stub's nothing, the hidden cases in results.json shown after
    the due date and never named in the summary a student sees at once.
What the bundle does in a fresh Debian 12 root (setup.sh's packages and build, the sandbox there)
is tried by hand: tests/tools/try-gradescope-root.sh.
"""
import json
import os
import re
import shutil
import stat
import subprocess
import sys
import zipfile

cmake, clothlab, stubgen, source, work = sys.argv[1:6]
problems = []


def problem(text):
    problems.append(text)
    print("PROBLEM:", text)


shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
out = os.path.join(work, "bundle")
subprocess.run([cmake, f"-DSOURCE={source}", f"-DOUT={out}", f"-DSTUBGEN={stubgen}",
                f"-DCLOTHLAB={clothlab}", "-DGRADESCOPE=ON", "-P",
                os.path.join(source, "tests/grade/harness/export_release.cmake")], check=True)

# --- the zip ----------------------------------------------------------------------------------
with zipfile.ZipFile(out + ".zip") as z:
    infos = {i.filename.rstrip("/"): i for i in z.infolist()}
tops = {name.split("/")[0] for name in infos}
if tops != {"setup.sh", "run_autograder", "clothlab"}:
    problem(f"the zip's top holds {sorted(tops)}, not setup.sh, run_autograder and clothlab/")
for script in ("setup.sh", "run_autograder"):
    info = infos.get(script)
    if info is None:
        continue
    if not (info.external_attr >> 16) & stat.S_IXUSR:
        problem(f"{script} is not executable in the zip")
    parsed = subprocess.run(["bash", "-n", os.path.join(out, script)], capture_output=True,
                            text=True)
    if parsed.returncode != 0:
        problem(f"bash cannot parse {script}: {parsed.stderr}")
for name, wanted in (("clothlab/CMakeLists.txt", True), ("clothlab/tests/grade-hidden", True),
                     ("clothlab/solutions", False), ("clothlab/tests/grade/harness/planted", False)):
    if (name in infos) != wanted:
        problem(f"the zip {'lacks' if wanted else 'holds'} {name}")
stubs = sorted(n for n in infos if re.fullmatch(r"clothlab/exercises/\d\d_\w+\.cpp", n))
if not stubs:
    problem("the zip holds no exercise file")
for name in stubs:
    restub = os.path.join(work, "restub.cpp")
    subprocess.run([stubgen, os.path.join(out, name), restub], check=True)
    with open(os.path.join(out, name), "rb") as a, open(restub, "rb") as b:
        if a.read() != b.read():
            problem(f"{name} is not the shipped stub")

# --- setup.sh's packages against what CMakeLists.txt requires ---------------------------------
with open(os.path.join(source, "CMakeLists.txt")) as f:
    cmakelists = f.read()
required = set(re.findall(r"^\s*clothlab_require\(\S+ \S+ ([^\s)]+)", cmakelists, re.M))
required |= {p for line in re.findall(r'^\s*"\s*sudo apt-get install -y ([^"$]+)"', cmakelists,
                                      re.M) for p in line.split()}
with open(os.path.join(out, "setup.sh")) as f:
    setup = f.read()
install = re.search(r"apt-get install -y((?:\\\n|[^\n])*)", setup)
installed = set(install.group(1).replace("\\\n", " ").split()) if install else set()
if len(required) < 6:
    problem(f"read too few required packages from CMakeLists.txt: {sorted(required)}")
missing = sorted(required - installed)
if missing:
    problem(f"setup.sh does not install {', '.join(missing)}, which CMakeLists.txt requires")

# --- run_autograder on a submission: lesson 01 solved, lesson 02's file broken ------------------
# Gradescope's layout, with the bundle's clothlab/build holding this build's grader, so that
# nothing is built but the submission.
root = os.path.join(work, "autograder")
shutil.copytree(out, os.path.join(root, "source"), symlinks=True)
build = os.path.join(root, "source/clothlab/build")
os.makedirs(build)
os.symlink(os.path.realpath(clothlab), os.path.join(build, "clothlab"))
submission = os.path.join(root, "submission")
os.makedirs(submission)
solutions = os.path.join(source, "solutions")
for name in os.listdir(solutions):
    if re.match(r"0[12]_\w+\.cpp$", name):
        shutil.copy(os.path.join(solutions, name), submission)
broken = [n for n in os.listdir(submission) if n.startswith("02_")][0]
with open(os.path.join(submission, broken), "a") as f:
    f.write("double typo = 1.0 +;  // does not compile\n")
graded = subprocess.run(["bash", os.path.join(root, "source/run_autograder")],
                        env=dict(os.environ, AUTOGRADER_ROOT=root, NO_COLOR="1"),
                        capture_output=True, text=True)
print(graded.stdout[-3000:], graded.stderr[-3000:])
results_path = os.path.join(root, "results/results.json")
if not os.path.exists(results_path):
    problem(f"run_autograder wrote no results.json (exit {graded.returncode})")
else:
    with open(results_path) as f:
        results = json.load(f)
    by_lesson = {}
    for t in results["tests"]:
        by_lesson.setdefault(t["name"][:4], []).append(t)
    ex01, ex02 = by_lesson.get("ex01", []), by_lesson.get("ex02", [])
    if not ex01 or not ex02:
        problem("results.json has no case of ex01 or of ex02")
    if any(t["score"] != t["max_score"] for t in ex01):
        problem("lesson 01, solved, lost points beside the broken file: "
                + "; ".join(t["name"] for t in ex01 if t["score"] != t["max_score"]))
    if any(t["score"] != 0 for t in ex02):
        problem("the broken lesson 02 scored points")
    error = re.compile(re.escape(broken) + r":\d+:\d+: error:")
    if not all("not compiled" in t["output"] and error.search(t["output"]) for t in ex02):
        problem("ex02's cases do not say the file did not compile, with the compiler's error")
    others = [t["name"] for lesson, cases in by_lesson.items() if lesson not in ("ex01", "ex02")
              for t in cases if t["score"] != 0]
    if others:
        problem(f"exercises not handed in scored points: {others}")
    expected = sum(t["max_score"] for t in ex01)
    if results["score"] != expected:
        problem(f"the score is {results['score']}, expected lesson 01's {expected}")
    hidden = [t for t in results["tests"] if t.get("visibility") != "visible"]
    if not hidden:
        problem("results.json has no hidden case")
    for t in hidden:
        if t.get("visibility") not in ("after_due_date", "after_published", "hidden"):
            problem(f"{t['name']} has visibility {t.get('visibility')}")
        if t["name"] in results["output"]:
            problem(f"the summary a student sees at once names the hidden case {t['name']}")

if problems:
    print(f"\n{len(problems)} problem(s) with the Gradescope bundle")
    sys.exit(1)
print("the Gradescope bundle is well formed, and run_autograder grades a broken file's "
      "exercises alone as not compiled")
