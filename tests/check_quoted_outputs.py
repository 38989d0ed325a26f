#!/usr/bin/env python3
"""Every program output a document quotes is what the build prints.

A quoted output block names the command that prints it in an HTML comment (invisible once
rendered) on the line right before its fence:

    <!-- output: ./build/lesson12 -->
    ```
    ...
    ```

Options follow the command, each after a '|':

    | timing: "wall [s]", "in # s"   numbers that measure time or speed: a column of a table,
                                     named by its header, or each '#' of a piece of a line (a
                                     number written in the piece is checked as usual). They are
                                     checked in shape only: present, not negative, and at most
                                     50 times the quoted figure (plus 1).
    | shape only                     every number in shape only (figures re-measured elsewhere).
    | checked with: COMMAND          run this quicker command instead, which prints the same
                                     numbers (say so in the text).
    | exit: N                        the command's exit code (0 unless given).
    | in: FOLDER                     run it beside the files of this folder of the project (the
                                     scenes a README example names as if they were at hand).

The command runs once, from a folder where `./build` is the build and `lessons` the lessons, and
every block that names it is checked against its output. Each quoted line must match an output
line, in order: the same words (blanks collapsed), and every number the same to the digits the
block shows (a quoted 0.9320 matches a printed 0.93204, not 0.9330). A line of "..." stands for
lines left out; a line that starts with "$ " is the command typed, not its output.

    check_quoted_outputs.py --source ROOT --build BUILD --work DIR [--timeout S] DOCUMENT...
"""

import argparse
import math
import os
import re
import shlex
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from decimal import Decimal

NUMBER = re.compile(r"[+-]?(?:\d+(?:\.\d+)?|\.\d+)(?:[eE][+-]?\d+)?")
MARK = re.compile(r"^\s*<!--\s*output:\s*(.*?)\s*-->\s*$")


def skeleton(line):
    """The line's words: numbers as '#', blanks collapsed."""
    return " ".join(NUMBER.sub("#", line).split())


def numbers(line):
    return [(m.group(0), m.start(), m.end()) for m in NUMBER.finditer(line)]


def half_unit(quoted):
    """Half a unit of the quoted number's last digit: how far the printed one may differ."""
    mantissa, _, exponent = quoted.lower().partition("e")
    places = len(mantissa.split(".")[1]) if "." in mantissa else 0
    return Decimal(5) * Decimal(10) ** (int(exponent or 0) - places - 1)


class Block:
    def __init__(self, document, line, command, options, lines):
        self.document, self.line, self.command, self.lines = document, line, command, lines
        self.timing, self.shape_only, self.run, self.folder = [], False, command, ""
        self.exit = 0
        for option in options:
            key, _, value = option.partition(":")
            key, value = key.strip(), value.strip()
            if key == "timing":
                self.timing = re.findall(r'"([^"]+)"', value)
                if not self.timing:
                    raise ValueError(f'{self.where()}: timing: expects "..." names, got {value!r}')
            elif key == "shape only":
                self.shape_only = True
            elif key == "checked with":
                self.run = value
            elif key == "exit":
                self.exit = int(value)
            elif key == "in":
                self.folder = value
            else:
                raise ValueError(f"{self.where()}: unknown option {key!r} (expected timing:, "
                                 "shape only, checked with:, exit: or in:)")

    def where(self, offset=0):
        return f"{self.document}:{self.line + offset}"

    def timing_places(self):
        """For each quoted line, the indices of its numbers that are timings."""
        columns = []  # (start, end) of a timing column's header
        for spec in self.timing:
            if "#" not in spec:
                for text in self.lines:
                    at = text.find(spec)
                    if at >= 0:
                        columns.append((at, at + len(spec)))
                        break
                else:
                    raise ValueError(f"{self.where()}: no header {spec!r} for timing: in the block")
        places = []
        for text in self.lines:
            found = set()
            spans = numbers(text)
            for index, (_, start, end) in enumerate(spans):
                # A right-aligned column: the number ends under its header's span.
                if any(c0 <= end <= c1 or c0 <= start < c1 for c0, c1 in columns):
                    found.add(index)
            marked = skeleton(text)
            for spec in self.timing:
                if "#" in spec:
                    # The spec's '#'s are timings; a number written in it is a figure.
                    kinds = [part == "#" for part in re.findall(r"#|" + NUMBER.pattern, spec)]
                    at = marked.find(skeleton(spec))
                    if at >= 0:
                        before = marked[:at].count("#")
                        found.update(before + k for k, timing in enumerate(kinds) if timing)
            places.append(found)
        return places


def read_blocks(root, document):
    text = open(os.path.join(root, document), encoding="utf-8").read().split("\n")
    blocks = []
    for i, line in enumerate(text):
        m = MARK.match(line)
        if not m:
            continue
        if i + 1 >= len(text) or not text[i + 1].startswith("```"):
            raise ValueError(f"{document}:{i + 1}: an output mark must stand right before a fence")
        j = i + 2
        while j < len(text) and not text[j].startswith("```"):
            j += 1
        if j == len(text):
            raise ValueError(f"{document}:{i + 2}: the fence is never closed")
        command, *options = [part.strip() for part in m.group(1).split("|")]
        if not command:
            raise ValueError(f"{document}:{i + 1}: an output mark must name its command")
        blocks.append(Block(document, i + 3, command, options, text[i + 2:j]))
    return blocks


def agrees(quoted, printed, timing):
    if timing:
        p = float(printed)
        return math.isfinite(p) and 0 <= p <= 50 * abs(float(quoted)) + 1
    return abs(Decimal(printed) - Decimal(quoted)) <= half_unit(quoted)


def check_block(block, output):
    problems = []
    cursor = 0
    timing = block.timing_places()
    for offset, (text, places) in enumerate(zip(block.lines, timing)):
        if not text.strip() or text.strip() in ("...", "…") or text.startswith("$ "):
            continue
        want = skeleton(text)
        quoted = numbers(text)
        if block.shape_only:
            places = set(range(len(quoted)))
        candidates = [k for k in range(cursor, len(output)) if skeleton(output[k]) == want]
        match = None
        for k in candidates:
            printed = numbers(output[k])
            if all(agrees(q[0], p[0], index in places)
                   for index, (q, p) in enumerate(zip(quoted, printed))):
                match = k
                break
        if match is not None:
            cursor = match + 1
            continue
        if candidates:
            cursor = candidates[0] + 1  # taken as this line's, so that the next is read after it
            problems.append(f"{block.where(offset)}: quoted  {text.strip()}\n"
                            f"    but the build prints  {output[candidates[0]].strip()}")
        else:
            problems.append(f"{block.where(offset)}: quoted  {text.strip()}\n"
                            f"    but `{block.run}` prints no such line after the lines matched "
                            "before it")
    return problems


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--source", required=True)
    parser.add_argument("--build", required=True)
    parser.add_argument("--work", required=True)
    parser.add_argument("--timeout", type=float, default=300)
    parser.add_argument("documents", nargs="+")
    args = parser.parse_args()

    # The commands read as the lessons write them, from the project's root: ./build/..., lessons/.
    def prepare(work, files):
        os.makedirs(work, exist_ok=True)
        for name, target in files:
            link = os.path.join(work, name)
            if os.path.islink(link):
                os.remove(link)
            os.symlink(os.path.abspath(target), link)
        return work

    prepare(args.work, (("build", args.build), ("lessons", os.path.join(args.source, "lessons"))))

    try:
        blocks = [b for d in args.documents for b in read_blocks(args.source, d)]
    except ValueError as error:
        print(f"error: {error}")
        return 1
    if not blocks:
        print("error: no quoted output is marked with <!-- output: COMMAND --> in "
              + ", ".join(args.documents))
        return 1

    outputs = {}
    problems = []
    def run(key):
        command, folder, code = key
        work = args.work
        if folder:
            # The folder's files linked into a work folder of their own, beside ./build.
            at = os.path.join(args.source, folder)
            if not os.path.isdir(at):
                return [f"in: {folder} is not a folder of the project"], None
            files = [(f, os.path.join(at, f)) for f in sorted(os.listdir(at))]
            work = prepare(os.path.join(args.work, folder.replace("/", "_")),
                           files + [("build", args.build)])
        try:
            done = subprocess.run(shlex.split(command), cwd=work, capture_output=True,
                                  text=True, timeout=args.timeout)
        except (OSError, subprocess.TimeoutExpired) as error:
            return [f"`{command}` could not run: {error}"], None
        trouble = []
        if done.returncode != code:
            trouble.append(f"`{command}` exited with {done.returncode}, not {code}:\n"
                           f"{done.stderr[-2000:]}")
        return trouble, (done.stdout + done.stderr).split("\n")

    # Two commands at a time: the lesson programs run one thread each.
    keys = list(dict.fromkeys((b.run, b.folder, b.exit) for b in blocks))
    with ThreadPoolExecutor(max_workers=2) as pool:
        for (command, folder, _), (trouble, output) in zip(keys, pool.map(run, keys)):
            problems += trouble
            if output is not None:
                outputs[command, folder] = output

    for block in blocks:
        if (block.run, block.folder) in outputs:
            problems += check_block(block, outputs[block.run, block.folder])

    lines = sum(len([t for t in b.lines if t.strip()]) for b in blocks)
    print(f"{len(blocks)} quoted outputs ({lines} lines) from {len(outputs)} commands checked")
    for problem in problems:
        print(problem)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
