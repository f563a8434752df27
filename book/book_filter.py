#!/usr/bin/env python3
"""Doxygen input filter for the chapters (FILTER_PATTERNS in book/Doxyfile.in).

Doxygen runs `book_filter.py chapters/NN-topic/chapter.md` and reads the page from stdout. The
filter adds what a book needs and plain Doxygen markdown cannot express, without changing the line
numbers of the source (so Doxygen's warnings still point at the right line):

- Exercise headings `### Exercise N.M {#label}` get their title from the exercise's marker in
  solutions/ (`// BEGIN EXERCISE N.M: title`), the single source of every exercise title.
- Figures `\\image html NAME.svg "caption"` (or NAME.png) are numbered per chapter ("Figure N.k: caption") and
  get the anchor `fig_NAME`; `\\figref{NAME}` in the text becomes a link "Figure N.k".
- Optional parts `\\if NAME` ... [`\\else` ...] `\\endif` (lines of their own, outside code
  blocks) are resolved here, against the sections given by `--sections=NAME,...` (which the build
  sets from the tools it found, in place of Doxygen's ENABLED_SECTIONS): the lines of the branch not
  taken, and the directives, become empty lines, so figures are numbered as the reader sees them.
- A number a demo computes reaches the text from the demo's own output at build time:
  `\\demo{FOLDER/values.txt#KEY}` is replaced by the value of `KEY = VALUE` in that file of the
  build's figures folder (`--figures=DIR`); a missing file or key is a BOOK ERROR, never a number
  copied by hand.
- Every chapter gets previous/next links, at the top (in place of the blank line after the title)
  and at the bottom, following the order of the chapter folders; the last chapter leads to the
  bibliography.

Problems (an exercise without a marker in solutions/, a heading that carries its own title, a
reference to an unknown figure, a `\\snippet` whose lines hold an exercise region's BEGIN or END
marker, which would print the solution) are written into the page as visible text starting with
"BOOK ERROR", which the book check (tests/book/check_book.py) refuses, and to stderr.
"""

from __future__ import annotations

import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))
import grbd_exercises as gx  # noqa: E402

EXERCISE = re.compile(r"^(?P<hashes>#{2,4})\s+Exercise\s+(?P<id>\d+\.\d+)(?P<rest>[^{]*?)\s*"
                      r"(?P<anchor>\{#\w+\})\s*$")
IMAGE = re.compile(r'^(?P<indent>\s*)\\image\s+html\s+(?P<file>(?P<name>[\w.-]+)\.(?:svg|png))\s+'
                   r'"(?P<caption>[^"]*)"(?P<rest>.*)$')
CONDITION = re.compile(r"^\s*\\(?P<directive>if|else|endif)\b\s*(?P<name>\w*)\s*$")
FENCE = re.compile(r"^\s*(```|~~~)")
FIGREF = re.compile(r"\\figref\{(?P<name>[\w.-]+)\}")
DEMO_VALUE = re.compile(r"\\demo\{(?P<file>[\w./-]+)#(?P<key>[\w.-]+)\}")
SNIPPET = re.compile(r"^\s*\\snippet\s+(?P<file>\S+)\s+(?P<tag>.+?)\s*$")
EXERCISE_MARKER = re.compile(r"//\s*(?:BEGIN|END) EXERCISE (?P<id>\d+\.\d+)")


def chapter_heading(text: str) -> re.Match | None:
    """The first line of a chapter page, '# Chapter N: Title {#label}', or None."""
    m = gx.CHAPTER_TITLE.match(text.split("\n", 1)[0])
    return m if m and m.group("label") else None


def figure_anchor(name: str) -> str:
    return "fig_" + name.replace("-", "_")


def chapter_pages() -> list[tuple[str, str]]:
    """(label, title) of every chapter, in the order of the chapter folders."""
    pages = []
    for path in sorted(ROOT.glob("chapters/[0-9][0-9]-*/chapter.md")):
        m = chapter_heading(path.read_text(encoding="utf-8"))
        if m:
            pages.append((m.group("label"), m.group("title")))
    return pages


def exercise_titles() -> dict[str, str]:
    """'N.M' -> title, from the markers in solutions/."""
    titles: dict[str, str] = {}
    for chapter_dir in gx.chapter_dirs(ROOT):
        for ex in gx.exercises_of(chapter_dir, ROOT):
            titles[ex.id] = ex.title
    return titles


def navigation(i: int, pages: list[tuple[str, str]], where: str) -> str:
    """One line of previous / contents / next links for the chapter pages[i]."""
    prev = f'\\ref {pages[i - 1][0]} "← {pages[i - 1][1]}"' if i > 0 else \
        '\\ref index "← The book"'
    nxt = f'\\ref {pages[i + 1][0]} "{pages[i + 1][1]} →"' if i + 1 < len(pages) else \
        '\\ref bibliography "Bibliography →"'
    return (f'<div class="grbd-nav grbd-nav-{where}">{prev} | \\ref index "Contents" | '
            f"{nxt}</div>")


def snippet_exercise(file: str, tag: str) -> str | None:
    """The exercise ('N.M') whose region the snippet `tag` of `file` shows any of, or None: the
    lines between the two `[tag]` markers, as Doxygen's \\snippet cuts them."""
    path = ROOT / file
    if not path.is_file():
        return None  # Doxygen itself warns about a missing file
    marker = f"[{tag}]"
    inside = False
    region = None  # the exercise whose region the current line is in
    for line in path.read_text(encoding="utf-8").split("\n"):
        if marker in line:
            if inside:
                return None
            if region:
                return region  # the snippet starts inside a region
            inside = True
            continue
        m = EXERCISE_MARKER.search(line)
        if m:
            if inside:
                return m.group("id")
            region = m.group("id") if "BEGIN" in m.group(0) else None
    return None


def demo_values(figures: pathlib.Path | None, file: str) -> dict[str, str] | None:
    """The `key = value` lines of a demo's values file in the build's figures folder, or None
    when there is none (no folder given, the demo did not run, the file is missing)."""
    if figures is None or not (figures / file).is_file():
        return None
    values = {}
    for line in (figures / file).read_text(encoding="utf-8").split("\n"):
        key, equals, value = line.partition("=")
        if equals and key.strip():
            values[key.strip()] = value.strip()
    return values


def book_error(message: str, path: pathlib.Path, line: int) -> str:
    print(f"{path}:{line}: book_filter: {message}", file=sys.stderr)
    return f"BOOK ERROR: {message}"


def resolve_sections(lines: list[str], sections: set[str], path: pathlib.Path) -> list[str]:
    """The lines with every `\\if NAME` block resolved: kept where NAME is in `sections`, else its
    `\\else` branch; dropped lines and the directives become empty lines (same line numbers)."""
    out: list[str] = []
    stack: list[tuple[bool, bool]] = []  # (this branch shown, the enclosing block shown)
    fenced = False
    for i, line in enumerate(lines):
        shown = all(branch for branch, _ in stack)
        if FENCE.match(line):
            fenced = not fenced
        condition = None if fenced else CONDITION.match(line)
        if condition is None:
            out.append(line if shown else "")
            continue
        directive, name = condition.group("directive"), condition.group("name")
        if directive == "if" and name:
            stack.append((name in sections, shown))
        elif directive == "else" and stack and not name:
            branch, outer = stack.pop()
            stack.append((not branch, outer))
        elif directive == "endif" and stack and not name:
            stack.pop()
        else:
            out.append(book_error(f"unmatched or malformed '{line.strip()}'", path, i + 1))
            continue
        out.append("")
    if stack:
        out.append(book_error("an \\if block is not closed by \\endif", path, len(lines)))
    return out


def filter_chapter(path: pathlib.Path, text: str, sections: set[str] | None = None,
                   figure_dir: pathlib.Path | None = None) -> str:
    m = chapter_heading(text)
    if not m:
        return text  # not a chapter page: leave it alone
    lines = resolve_sections(text.split("\n"), sections or set(), path)
    number, label = int(m.group("number")), m.group("label")
    pages = chapter_pages()
    labels = [page_label for page_label, _ in pages]
    position = labels.index(label) if label in labels else None
    titles = exercise_titles()

    # Number the figures first, so that \figref may point forward.
    figures: dict[str, str] = {}
    for line in lines:
        image = IMAGE.match(line)
        if image:
            figures.setdefault(image.group("name"), f"Figure {number}.{len(figures) + 1}")

    out = []
    for i, line in enumerate(lines):
        heading = EXERCISE.match(line)
        image = IMAGE.match(line)
        snippet = SNIPPET.match(line)
        shown = snippet and snippet_exercise(snippet.group("file"), snippet.group("tag"))
        if shown:
            line = book_error(f"\\snippet {snippet.group('file')} {snippet.group('tag')} shows "
                              f"the region of Exercise {shown}, which the reader is to write: "
                              "quote the declaration, or a part outside the region", path, i + 1)
        elif heading:
            ex_id, rest = heading.group("id"), heading.group("rest").strip()
            if rest:
                line = book_error(f"the heading of Exercise {ex_id} carries its own title "
                                  f"'{rest}'; write '{heading.group('hashes')} Exercise {ex_id} "
                                  f"{heading.group('anchor')}' and keep the title in the "
                                  "solution's BEGIN EXERCISE marker", path, i + 1)
            elif ex_id not in titles:
                line = book_error(f"Exercise {ex_id} has no '// BEGIN EXERCISE {ex_id}: title' "
                                  "marker in solutions/", path, i + 1)
            else:
                line = (f"{heading.group('hashes')} Exercise {ex_id}: {titles[ex_id]} "
                        f"{heading.group('anchor')}")
        elif image:
            name = image.group("name")
            line = (f'{image.group("indent")}\\anchor {figure_anchor(name)} '
                    f'\\image html {image.group("file")} '
                    f'"{figures[name]}: {image.group("caption")}"{image.group("rest")}')

        def figref(ref: re.Match) -> str:
            name = ref.group("name")
            if name not in figures:
                return book_error(f"\\figref{{{name}}}: no figure {name}.svg in this chapter",
                                  path, i + 1)
            return f'\\ref {figure_anchor(name)} "{figures[name]}"'

        line = FIGREF.sub(figref, line)

        def demo_value(ref: re.Match) -> str:
            values = demo_values(figure_dir, ref.group("file"))
            if values is None:
                return book_error(f"\\demo{{{ref.group('file')}#{ref.group('key')}}}: no file "
                                  f"{ref.group('file')} in the figures folder {figure_dir} (run the "
                                  "demo: the build's target figures)", path, i + 1)
            if ref.group("key") not in values:
                return book_error(f"\\demo{{{ref.group('file')}#{ref.group('key')}}}: the demo "
                                  f"wrote no value {ref.group('key')}", path, i + 1)
            return values[ref.group("key")]

        line = DEMO_VALUE.sub(demo_value, line)
        if i == 1 and not line.strip() and position is not None:
            line = navigation(position, pages, "top")
        out.append(line)
    if position is not None:
        while out and not out[-1].strip():
            out.pop()
        out += ["", navigation(position, pages, "bottom"), ""]
    return "\n".join(out)


def main() -> int:
    args = sys.argv[1:]
    sections: set[str] = set()
    figures: pathlib.Path | None = None
    while args and args[0].startswith("--"):
        option = args.pop(0)
        if option.startswith("--sections="):
            sections = {name for name in option[len("--sections="):].split(",") if name}
        elif option.startswith("--figures="):
            figures = pathlib.Path(option[len("--figures="):])
        else:
            args = []
            break
    if len(args) != 1:
        print("usage: book_filter.py [--sections=NAME,...] [--figures=DIR] <page.md>  (a Doxygen "
              "INPUT_FILTER)", file=sys.stderr)
        return 2
    path = pathlib.Path(args[0])
    text = path.read_text(encoding="utf-8")
    sys.stdout.write(filter_chapter(path, text, sections, figures))
    return 0


if __name__ == "__main__":
    sys.exit(main())
