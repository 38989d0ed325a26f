#!/usr/bin/env python3
"""Writes one lesson's live page: the shell page.html with three.js, the engine module (and, on
a student page, the reference module), the renderer, the page's script and the lesson's scenes
put in place of its markers. The result is one file that
needs no network and opens from file://."""

import argparse
import json
import pathlib
import re
import sys


def script_text(path: pathlib.Path) -> str:
    """A script to put inside <script>...</script>: nothing in it may close or confuse the
    element, which the checks below make sure of rather than rewrite code."""
    text = path.read_text(encoding="utf-8")
    lowered = text.lower()
    for bad in ("</script", "<!--", "<script"):
        if bad in lowered:
            sys.exit(f"make_page: {path} holds '{bad}', which would break an inline <script>")
    return text


def reference_script(path: pathlib.Path) -> str:
    """The reference module (the lesson page's own, built on solutions/) for a student page's
    side-by-side mode. It names its factory createClothlab, as the student's module does: run
    inside a function, its name stays there, and the function hands the factory out as
    createClothlabReference. One module linked once serves both pages."""
    text = script_text(path)
    if not re.search(r"\bvar createClothlab\b", text):
        sys.exit(f"make_page: {path} does not define createClothlab (built with another "
                 "EXPORT_NAME?)")
    return ("<script>\nvar createClothlabReference = (function () {\n" + text +
            "\nreturn createClothlab;\n})();\n</script>")


def safe_json(value) -> str:
    """JSON whose <, > and & are \\u escapes: no text in it can end the <script> it sits in."""
    text = json.dumps(value, ensure_ascii=False)
    return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def html_escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    for option in ("lesson", "shell", "script", "render", "three", "orbit", "module", "out",
                   "kernels"):
        parser.add_argument(f"--{option}", required=True)
    parser.add_argument("--reference", help="the reference module (the lesson page's), for a "
                        "student page's side-by-side mode, where its factory is "
                        "createClothlabReference")
    args = parser.parse_args()

    lesson = pathlib.Path(args.lesson)
    readme = (lesson / "README.md").read_text(encoding="utf-8")
    heading = re.search(r"^#\s+(.+)$", readme, re.MULTILINE)
    title = heading.group(1).strip() if heading else lesson.name
    # The scenes in the order the lesson's text first names them: the one it starts with first.
    def first_named(scene: pathlib.Path):
        at = readme.find(scene.name)
        return (at if at >= 0 else len(readme), scene.name)
    scenes = []
    # Lesson 12's bake-off cloths of real size are the bench's (`bench methods --large`): a frame
    # of theirs is hundreds of explicit steps of a 48 x 48 cloth, too slow to watch in a page.
    for scene in sorted(lesson.glob("*.toml"), key=first_named):
        if scene.name.startswith("bakeoff-large-"):
            continue
        scenes.append({"name": f"lessons/{lesson.name}/{scene.name}",
                       "text": scene.read_text(encoding="utf-8")})
    data = {"lesson": lesson.name, "title": title, "kernels": args.kernels, "scenes": scenes}

    page = pathlib.Path(args.shell).read_text(encoding="utf-8")
    student = args.kernels != "solutions"
    parts = {
        "<!--CLOTHLAB_TITLE-->": html_escape(title + (" (your code)" if student else "")),
        "<!--CLOTHLAB_LIBRARIES-->": "<script>" + script_text(pathlib.Path(args.three)) +
                                     "</script>\n<script>" +
                                     script_text(pathlib.Path(args.orbit)) + "</script>",
        "<!--CLOTHLAB_MODULE-->": "<script>" + script_text(pathlib.Path(args.module)) +
                                  "</script>",
        "<!--CLOTHLAB_REFERENCE-->": reference_script(pathlib.Path(args.reference))
                                     if args.reference else "",
        "<!--CLOTHLAB_RENDER-->": "<script>" + script_text(pathlib.Path(args.render)) +
                                  "</script>",
        "<!--CLOTHLAB_SCRIPT-->": "<script>" + script_text(pathlib.Path(args.script)) +
                                  "</script>",
        "/*CLOTHLAB_LESSON*/": safe_json(data),
    }
    for marker, text in parts.items():
        if page.count(marker) != 1:
            sys.exit(f"make_page: {args.shell} must hold {marker} exactly once")
        page = page.replace(marker, text)
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    partial = out.with_name("." + out.name + ".partial")
    partial.write_text(page, encoding="utf-8")
    partial.replace(out)


if __name__ == "__main__":
    main()
