#!/usr/bin/env python3
"""check_reports.py CLOTHLAB CASES WORK_DIR: grades grader-selftest-reports (selftest_reports.cpp)
and reads every report as its reader would.

What a student sees (results.json's top-level output, which Gradescope shows at once, the outputs
of the visible tests, and the whole output with --autolab, which Autolab shows) holds nothing of
a case that is not visible now: no name, hint, message, expected value or points of one, and a
table whose points are those of the visible cases; and the visible cases run first, so that none
prints what a hidden one left behind. The grader's own output and the test entries
of the hidden cases keep everything, for the instructor; results.json marks the grader's output
as the instructor's alone.

Names and messages are shown escaped on one line: no line of any report but the real total reads
"Total: ...". The JUnit XML parses with a real XML parser, and results.json as strict UTF-8 JSON,
whatever bytes the names, messages and output hold."""

import json
import pathlib
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ElementTree

clothlab, cases, work = (pathlib.Path(arg).resolve() for arg in sys.argv[1:4])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
problems = []


def problem(text):
    problems.append(text)


def grade(*args):
    # A hidden case leaves a file here, which a visible case prints if it runs later.
    (work / "left-behind-by-a-hidden-case.txt").unlink(missing_ok=True)
    run = subprocess.run([clothlab, "grade", "--binary", str(cases), "--timeout", "5", *args],
                         env={"NO_COLOR": "1", "PATH": "/usr/bin:/bin"}, cwd=work,
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, check=False)
    text = run.stdout.decode("utf-8", errors="replace")
    print(f"--- clothlab grade {' '.join(args)}: exit {run.returncode}\n{text}")
    if run.returncode != 0:
        problem(f"clothlab grade {' '.join(args)} exited with {run.returncode}")
    return text


results, junit = work / "results.json", work / "junit.xml"
graders_view = grade("--results", str(results), "--junit", str(junit))
autolab_view = grade("--autolab")

# --- the reports parse ---------------------------------------------------------------------------
try:
    report = json.loads(results.read_bytes().decode("utf-8"))  # strict: invalid UTF-8 raises
except (UnicodeDecodeError, json.JSONDecodeError) as e:
    sys.exit(f"check_reports: results.json is not valid UTF-8 JSON: {e}")
try:
    xml = ElementTree.parse(junit).getroot()
except ElementTree.ParseError as e:
    sys.exit(f"check_reports: the JUnit XML is not well-formed: {e}")

tests = report["tests"]
if len(tests) != 10 or len(xml.findall(".//testcase")) != 10:
    problem(f"results.json has {len(tests)} tests and the JUnit XML "
            f"{len(xml.findall('.//testcase'))} testcases, expected 10")

# --- nothing of a case not visible now reaches a student --------------------------------------
top = report["output"]
if "SECRET" in top:
    problem("results.json's top-level output, which every student sees, shows a hidden case:\n"
            + top)
for test in tests:
    secret = "SECRET" in test["name"]
    if secret == (test["visibility"] == "visible"):
        problem(f"{test['name']!r} has visibility {test['visibility']}")
    if test["visibility"] == "visible" and "SECRET" in test["output"]:
        problem(f"the visible test {test['name']!r} shows a hidden case:\n{test['output']}")
# The student's table: ex93.1's visible cases only (2 of their 5 points), no row for ex94.1, whose
# case is hidden, and the total of the visible cases (9 points) with the others counted.
if not re.search(r"^ex93\.1 +2 / 5 +1 / 2 +failing$", top, re.M):
    problem("the student's table does not give ex93.1 the 2 / 5 points of its visible cases")
if re.search(r"^ex94\.1 ", top, re.M):
    problem("the student's table has a row for ex94.1, whose only case is hidden")
if not re.search(r"^Total: 2 / 9 points\n4 more cases are graded, not shown here", top, re.M):
    problem("the student's total is not 2 / 9 points, followed by the count of the 4 cases "
            "not shown")
if "SECRET" in autolab_view:
    problem("with --autolab (Autolab shows the whole output to the student) the output shows a "
            "hidden case")
if report.get("stdout_visibility") != "hidden":
    problem("results.json does not keep the grader's output from students (stdout_visibility)")
# The grade itself counts every case, and the instructor's view shows them all.
if report["score"] != 8:
    problem(f"results.json's score is {report['score']}, expected 8 (two cases of ex93.1)")
for text in ["SECRET-NAME-A", "SECRET-HINT-A", "SECRET-MESSAGE-B", "Total: 8 / 31 points"]:
    if text not in graders_view:
        problem(f"the grader's own output does not say {text!r}")
if not re.search(r'"ex93\.1": ?8\b', autolab_view.strip().splitlines()[-1]):
    problem("Autolab's score for ex93.1 is not 8, hidden cases included")

# --- names and messages on one line ----------------------------------------------------------
# The texts as the student or the instructor reads them, but for what a case printed itself
# (shown below "output:" in its own test, as printed).
texts = {"the grader's output": graders_view, "the output with --autolab": autolab_view,
         "results.json's top-level output": top}
for test in tests:
    texts[f"results.json's test {test['name']!r}"] = test["output"].split("\noutput:\n")[0]
for case in xml.iter("testcase"):
    for failure in case.iter("failure"):
        texts[f"the JUnit failure of {case.get('name')!r}"] = (
            failure.get("message") + "\n" + (failure.text or ""))
for where, text in texts.items():
    fake = [line for line in text.splitlines() if re.match(r"\s*Total: 130 / 130", line)]
    if fake:
        problem(f"{where} has a line drawn by a name or a message: {fake[0]!r}")
    if "\x1b" in text:
        problem(f"{where} holds an escape character")
    for ch in ["\r", "\u2028", "\u202e"]:
        if ch in text:
            problem(f"{where} holds {ch!r}, which breaks or reorders a line")
names = [test["name"] for test in tests] + [case.get("name") for case in xml.iter("testcase")]
names += [case.get("file") for case in xml.iter("testcase")]
for name in names:
    if len(name.splitlines()) > 1 or "\x1b" in name:
        problem(f"the name {name!r} is not on one line")
escaped = [
    r"ex96.1 a name that breaks the line\n\nTotal: 130 / 130 points: failed",
    r"threw an exception: boom\n\nTotal: 130 / 130 points\n",
    r"selftest_reports\u2028Total: 130 / 130 points^[[2J.cpp:4: CHECK( 1 == 2 ) failed",
    r"controls ^A^K^[[2J, C1 ^?, lone ?, cut ??, return \r, separator \u2028, reversed \u202E",
    r"surrogate ???, overlong ?? and ???, past U+10FFFF ????",
]
for text in escaped:
    if text not in graders_view:
        problem(f"the grader's output does not show {text!r}")
# XML forbids U+FFFE and U+FFFF, which JSON allows: the JUnit name has "?" in its place.
if not any("U+FFFF ? and a surrogate ???" in case.get("name") for case in xml.iter("testcase")):
    problem("the JUnit XML does not show U+FFFF and the surrogate in ex97.1's name as '?'")

if problems:
    sys.exit("check_reports: " + "\ncheck_reports: ".join(problems))
print("every report shows a student only the visible cases, and every name on one line")
