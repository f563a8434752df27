#!/usr/bin/env python3
"""Doxygen input filter for the chapters (FILTER_PATTERNS in book/Doxyfile.in).

Doxygen runs `book_filter.py chapters/NN-topic/chapter.md` and reads the page from stdout. The
filter adds what a book needs and plain Doxygen markdown cannot express, without changing the line
numbers of the source (so Doxygen's warnings still point at the right line):

- Exercise headings `### Exercise N.M {#label}` get their title from the exercise's marker in
  solutions/ (`// BEGIN EXERCISE N.M: title`), the single source of every exercise title.
- Figures `\\image html NAME.svg "caption"` (or NAME.png) are numbered per chapter ("Figure N.k: caption") and
  get the anchor `fig_NAME`; `\\figref{NAME}` in the text becomes a link "Figure N.k".
- A caption writes its mathematics as the text does, `\\f$\\varepsilon_N\\f$`. Doxygen does not parse
  formulas in a caption (it warns "Illegal command"), but it copies a caption's text literally,
  backslashes halved, into the HTML, where MathJax typesets `\\(...\\)` as it does the text's own
  inline formulas; so the filter writes each `\\f$...\\f$` of a caption as `\\\\(...\\\\)` with every
  backslash doubled. A plain-text subscript outside the formulas of a caption (a letter or digit,
  `_` and a letter or digit not followed by a lower-case letter, as in `ε_N`, `A_IK`, `W_aᵀ`,
  while `find_pairs` is a name; or a Greek letter followed by a digit, `ω2`) is a BOOK ERROR:
  it belongs in a formula.
- Optional parts `\\if NAME` ... [`\\else` ...] `\\endif` (lines of their own, outside code
  blocks) are resolved here, against the sections given by `--sections=NAME,...` (which the build
  sets from the tools it found, in place of Doxygen's ENABLED_SECTIONS): the lines of the branch not
  taken, and the directives, become empty lines, so figures are numbered as the reader sees them.
- A number a demo computes reaches the text from the demo's own output at build time:
  `\\demo{FOLDER/values.txt#KEY}` is replaced by the value of `KEY = VALUE` in that file of the
  build's figures folder (`--figures=DIR`); a missing file or key is a BOOK ERROR, never a number
  copied by hand.
- A table that says it is a demo's output must take its numbers from it. The rule, which sees
  tables only (in prose a program cannot tell the numbers of a problem's set-up from its results):
  a markdown table *claims* a demo's output when the text that introduces it (its lines back to
  the previous heading, figure, table, code block or snippet: CONTEXT_END) names an output file in
  backticks (`` `convergence.txt` ``, `` `scaling.csv` ``), says "(from `", "the demo measured"
  (measures, prints, printed, writes, wrote, finds, found), "the demo's output" or "when the book
  is built" (DEMO_CLAIM). In such a table every body row (not the header) is checked, every cell
  but the first (which names the row): a cell whose whole text is a literal number (LITERAL_NUMBER:
  an optional <, >, ≈ or ~, a signed decimal number with digits grouped by spaces or commas, an
  optional exponent as e-5 or \\cdot10^{-5}, an optional ± part and a parenthesised number, an
  optional unit, ° or %, in or out of \\f$...\\f$ and **) is a BOOK ERROR, written in place of its
  row: the number must be a `\\demo{...}`. An introduction that says the table was "measured once"
  or made "once by hand" (MEASURED_ONCE: a benchmark measured once with a named program) exempts
  its table.
- The experiments (demos that run for minutes: `--experiments=NAME,...`, their figure names and
  data folders) are drawn by README command (1) only; where this build has not drawn one, its
  figure becomes the stand-in `standin_NAME.svg` (book/CMakeLists.txt writes it), its caption
  says so, and its `\\demo{NAME/values.txt#KEY}` values read "?". Every other missing figure or
  value stays an error.
- Every chapter gets previous/next links, at the top (in place of the blank line after the title)
  and at the bottom, following the order of the chapter folders; the last chapter leads to the
  bibliography.

Problems (an exercise without a marker in solutions/, a heading that carries its own title, a
reference to an unknown figure, a `\\snippet` whose lines hold an exercise region's BEGIN or END
marker, which would print the solution, a missing demo value, a table that claims a demo's output
but holds a number written by hand, a plain-text subscript in a caption) are written into the page
as visible text starting with "BOOK ERROR", which the book check (tests/book/check_book.py)
refuses, and to stderr.
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
FORMULA = re.compile(r"\\f\$(?P<tex>.*?)\\f\$")
# A plain-text subscript in a caption: "ε_N", "A_IK", "W_aᵀ" (not "find_pairs"), "ω2".
PLAIN_SUBSCRIPT = re.compile(r"[^\W_]_[^\W_](?![a-z])|[α-ωΑ-Ω][0-9]")
# What makes the text that introduces a table claim that the table is a demo's output.
DEMO_CLAIM = re.compile(r"`[\w./-]+\.(?:txt|csv)`|\(from `|\bthe demo (?:measured|measures|prints|"
                        r"printed|writes|wrote|finds|found)\b|\bthe demo's output\b|"
                        r"\bwhen the book is built\b", re.I)
# What exempts it: the table was measured once, by hand (a benchmark).
MEASURED_ONCE = re.compile(r"\bmeasured once\b|\bonce by hand\b", re.I)
TABLE_ROW = re.compile(r"^\s*\|")
# Where the text that introduces a table begins: after a heading, a figure, a table, a code block
# or a snippet.
CONTEXT_END = re.compile(r"^\s*(?:#|\||```|~~~|\\image\b|\\snippet\b|\\anchor\b)")
TABLE_DELIMITER = re.compile(r"^\s*\|?\s*:?-{3,}")
# A table cell that is nothing but a number (after \f$, \, and ** are removed): "618", "> 3000",
# "15 700", "2.74\cdot10^{-3} rad", "1.0e-08", "11.2 ± 0.2°", "13.5 ms", "0.022 %",
# "> 3000 (2.9\cdot10^{-3})".
_NUMBER = (r"[-+−]?\d[\d ,.]*(?:(?:\\cdot|\\times|×|·)\s*10\^\{?[-+−]?\d+\}?|[eE][-+−]?\d+)?")
LITERAL_NUMBER = re.compile(rf"^(?:[<>≈~≤≥]\s*)?{_NUMBER}(?:\s*(?:±|\\pm)\s*{_NUMBER})?"
                            rf"(?:\s*\(\s*{_NUMBER}\s*\))?"
                            r"\s*(?:%|°|[^\W\d_][^\W\d]*(?:[ /][^\W\d_][^\W\d]*)*)?$")
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


def caption_html(caption: str) -> str:
    """A caption as Doxygen must be given it for MathJax to typeset its formulas: each
    `\\f$TEX\\f$` becomes `\\\\(TEX\\\\)` with every backslash of TEX doubled (Doxygen halves them)."""
    return FORMULA.sub(lambda m: "\\\\(" + m.group("tex").replace("\\", "\\\\") + "\\\\)", caption)


def plain_subscript(caption: str) -> str | None:
    """The first plain-text subscript outside the formulas of a caption ("ε_N", "ω2"), or None."""
    m = PLAIN_SUBSCRIPT.search(FORMULA.sub(" ", caption))
    return m.group(0) if m else None


def table_cells(row: str) -> list[str]:
    """The cells of a markdown table row, split at the bars that are not escaped (`\\|` is the norm
    bar of a formula)."""
    cells = re.split(r"(?<!\\)\|", row.strip())
    if cells and not cells[0].strip():
        cells = cells[1:]
    if cells and not cells[-1].strip():
        cells = cells[:-1]
    return [cell.strip() for cell in cells]


def is_literal_number(cell: str) -> bool:
    text = cell.replace("\\f$", "").replace("\\,", " ").replace("**", "").strip()
    return bool(text) and LITERAL_NUMBER.match(text) is not None


def demo_table_problems(lines: list[str]) -> dict[int, str]:
    """{line index: problem} for the rows of the tables that claim a demo's output (DEMO_CLAIM in
    the text that introduces them) but hold a literal number (see the module's documentation)."""
    problems: dict[int, str] = {}
    fenced = False
    i = 0
    while i < len(lines):
        if FENCE.match(lines[i]):
            fenced = not fenced
        if fenced or not TABLE_ROW.match(lines[i]):
            i += 1
            continue
        start = i
        while i < len(lines) and TABLE_ROW.match(lines[i]):
            i += 1
        paragraph = []  # the text above the table, back to a heading, figure, table or code
        above = start - 1
        while above >= 0 and not CONTEXT_END.match(lines[above]):
            paragraph.insert(0, lines[above].strip())
            above -= 1
        context = " ".join(paragraph)
        claim = DEMO_CLAIM.search(context)
        if not claim or MEASURED_ONCE.search(context):
            continue
        for row in range(start + 1, i):
            if TABLE_DELIMITER.match(lines[row]):
                continue
            literal = next((cell for cell in table_cells(lines[row])[1:]
                            if is_literal_number(cell)), None)
            if literal is not None:
                problems[row] = (f"the text before this table says it is a demo's output "
                                 f"('{claim.group(0)}'), but its cell '{literal}' is a number "
                                 "written by hand: take it from the demo with "
                                 "\\demo{FOLDER/values.txt#KEY}, or say that the table was "
                                 "measured once by hand, with which program")
    return problems


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


def stand_in(name: str, figure_dir: pathlib.Path | None, experiments: set[str]) -> bool:
    """True when the figure NAME is an experiment's (a demo that runs for minutes, built by the
    target `figures` of README command (1) only) and this build has not drawn it: the book then
    shows the stand-in standin_NAME.svg that book/CMakeLists.txt writes."""
    if name not in experiments or figure_dir is None:
        return False
    return not any((figure_dir / f"{name}.{ext}").exists() for ext in ("svg", "png"))


def filter_chapter(path: pathlib.Path, text: str, sections: set[str] | None = None,
                   figure_dir: pathlib.Path | None = None,
                   experiments: set[str] | None = None) -> str:
    experiments = experiments or set()
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

    tables = demo_table_problems(lines)

    out = []
    for i, line in enumerate(lines):
        if i in tables:
            out.append(book_error(tables[i], path, i + 1))
            continue
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
            name, caption = image.group("name"), image.group("caption")
            subscript = plain_subscript(caption)
            if subscript:
                line = book_error(f"the caption of {image.group('file')} writes the subscript "
                                  f"'{subscript}' as plain text: write it as a formula, "
                                  "\\f$...\\f$, as the text does", path, i + 1)
            elif stand_in(name, figure_dir, experiments):
                line = (f'{image.group("indent")}\\anchor {figure_anchor(name)} '
                        f'\\image html standin_{name}.svg '
                        f'"{figures[name]}: {caption_html(caption)} (A stand-in: this build '
                        f'has not run the experiment, which ./scripts/demo runs; the figure is '
                        f'not drawn by this build.)"{image.group("rest")}')
            else:
                line = (f'{image.group("indent")}\\anchor {figure_anchor(name)} '
                        f'\\image html {image.group("file")} '
                        f'"{figures[name]}: {caption_html(caption)}"{image.group("rest")}')

        def figref(ref: re.Match) -> str:
            name = ref.group("name")
            if name not in figures:
                return book_error(f"\\figref{{{name}}}: no figure {name}.svg in this chapter",
                                  path, i + 1)
            return f'\\ref {figure_anchor(name)} "{figures[name]}"'

        line = FIGREF.sub(figref, line)

        def demo_value(ref: re.Match) -> str:
            values = demo_values(figure_dir, ref.group("file"))
            folder = ref.group("file").split("/", 1)[0]
            if values is None and stand_in(folder, figure_dir, experiments):
                return "?"  # the experiment has not run: its figure is a stand-in too
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
    experiments: set[str] = set()
    while args and args[0].startswith("--"):
        option = args.pop(0)
        if option.startswith("--sections="):
            sections = {name for name in option[len("--sections="):].split(",") if name}
        elif option.startswith("--figures="):
            figures = pathlib.Path(option[len("--figures="):])
        elif option.startswith("--experiments="):
            experiments = {name for name in option[len("--experiments="):].split(",") if name}
        else:
            args = []
            break
    if len(args) != 1:
        print("usage: book_filter.py [--sections=NAME,...] [--figures=DIR] [--experiments=NAME,...] "
              "<page.md>  (a Doxygen INPUT_FILTER)", file=sys.stderr)
        return 2
    path = pathlib.Path(args[0])
    text = path.read_text(encoding="utf-8")
    sys.stdout.write(filter_chapter(path, text, sections, figures, experiments))
    return 0


if __name__ == "__main__":
    sys.exit(main())
