#!/usr/bin/env python3
"""Checks that every link to a Markdown file of the repository, and to a heading in it, resolves.

usage: check_links.py [REPOSITORY]   (default: the folder above this script's)

Looks at the repository's Markdown files (every `*.md` outside `.ws/`, `.git/`, `build/`,
`devel/`) for links `[text](path.md#anchor)`, `[text](path.md)` and `[text](#anchor)` outside
code blocks and code spans, resolved from the linking file's folder as GitHub resolves them, and
at the other text files (sources, launch files, scenes, scripts) for `path.md#anchor`, resolved
from the repository's root, as a comment writes it (`doc/model.md#lasting-contact`). A link
resolves when its file exists and, with an anchor, one of that file's headings has that anchor
by GitHub's rule: the heading's text lowercased, every character but letters, digits, spaces,
'-' and '_' removed, spaces turned into '-'; a heading whose anchor is taken already gets '-1',
'-2', ... Prints each link that does not resolve (file:line: link: why) and exits 1 when there
is one, else prints how many links it checked and exits 0.
"""
import os
import pathlib
import re
import sys

SKIPPED_FOLDERS = {".ws", ".git", "build", "devel", "install", "__pycache__"}
TEXT_SUFFIXES = {".cpp", ".h", ".py", ".sh", ".launch", ".yaml", ".xml", ".cfg", ".msg", ".srv",
                 ".test", ".txt", ".rviz", ".urdf"}
MARKDOWN_LINK = re.compile(r"\]\(([^()\s]*(?:\([^()\s]*\)[^()\s]*)*)\)")
PLAIN_LINK = re.compile(r"([\w./-]+\.md)#([\w-]+)")
FENCE = re.compile(r"^\s*(```|~~~)")
HEADING = re.compile(r"^ {0,3}(#{1,6})\s+(.*?)\s*#*\s*$")


def files_of(repository):
    for folder, folders, names in os.walk(repository):
        folders[:] = sorted(name for name in folders if name not in SKIPPED_FOLDERS)
        for name in sorted(names):
            yield pathlib.Path(folder) / name


def lines_outside_code(text):
    """(line number, line) of each line outside fenced code blocks, code spans blanked."""
    fenced = False
    for number, line in enumerate(text.splitlines(), 1):
        if FENCE.match(line):
            fenced = not fenced
            continue
        if not fenced:
            yield number, re.sub(r"`[^`]*`", lambda span: " " * len(span.group(0)), line)


def heading_text(markdown):
    """A heading's text as GitHub renders it: links as their text, emphasis and code marks gone."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", markdown)
    return re.sub(r"<[^>]+>", "", text)


def anchor_of(text):
    text = heading_text(text).strip().lower()
    text = "".join(c for c in text if c.isalnum() or c in " -_")
    return text.replace(" ", "-")


def anchors_of(path, cache={}):
    if path not in cache:
        anchors, seen = set(), {}
        fenced = False
        for line in path.read_text(encoding="utf-8").splitlines():
            if FENCE.match(line):
                fenced = not fenced
                continue
            match = None if fenced else HEADING.match(line)
            if match:
                anchor = anchor_of(match.group(2))
                count = seen.get(anchor, 0)
                seen[anchor] = count + 1
                anchors.add(anchor if count == 0 else f"{anchor}-{count}")
        cache[path] = anchors
    return cache[path]


def problem(target, anchor):
    """Why a link to target#anchor does not resolve, or None when it does."""
    if not target.is_file():
        return "no such file"
    if anchor and anchor not in anchors_of(target):
        return f"no heading with the anchor '{anchor}' in {target.name}"
    return None


def main():
    repository = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else
                              pathlib.Path(__file__).resolve().parent.parent).resolve()
    checked, broken = 0, []
    for path in files_of(repository):
        relative = path.relative_to(repository)
        if relative == pathlib.Path("scripts", "check_links.py"):
            continue  # its own docstring's examples
        if path.suffix == ".md":
            text = path.read_text(encoding="utf-8")
            for number, line in lines_outside_code(text):
                for match in MARKDOWN_LINK.finditer(line):
                    link = match.group(1)
                    if re.match(r"^[a-z][a-z0-9+.-]*:", link):  # https:, mailto:, ...
                        continue
                    file_part, _, anchor = link.partition("#")
                    if file_part and not file_part.endswith(".md"):
                        continue  # a picture, a source file: GitHub shows them, no heading
                    target = (path.parent / file_part).resolve() if file_part else path
                    checked += 1
                    why = problem(target, anchor)
                    if why:
                        broken.append(f"{relative}:{number}: {link}: {why}")
        elif path.suffix in TEXT_SUFFIXES:
            try:
                text = path.read_text(encoding="utf-8")
            except UnicodeDecodeError:
                continue
            for number, line in enumerate(text.splitlines(), 1):
                for match in PLAIN_LINK.finditer(line):
                    target = (repository / match.group(1)).resolve()
                    checked += 1
                    why = problem(target, match.group(2))
                    if why:
                        broken.append(f"{relative}:{number}: {match.group(0)}: {why}")
    for line in broken:
        print(line)
    if broken:
        print(f"{len(broken)} of {checked} links to Markdown files do not resolve")
        return 1
    print(f"all {checked} links to Markdown files resolve")
    return 0


if __name__ == "__main__":
    sys.exit(main())
