#!/usr/bin/env python3
"""Checks on the built book (build/book/html) that a reader would otherwise find by hand:

- navigation: the main page and the "Chapters" page list the chapters in their order, the sidebar
  tree holds every chapter and the bibliography, and every chapter has previous/next links that
  lead to its neighbours;
- the mathematics is typeset by a local MathJax that is part of the book's own tree (real files,
  no links, so a copy of the folder keeps its mathematics), never loaded from the network, with
  every displayed equation numbered;
- every image and script a page refers to exists in the tree, and no page loads anything from the
  network;
- written chapters quote code (\\snippet fragments), show numbered figures, and contain mathematics;
- no snippet marker ("[product declaration]") stands in for a function's documentation, and no
  markdown markup (**, `, \\f$) is left unrendered in the text;
- every exercise heading carries the title of the exercise's marker in solutions/, and the text
  names its sources (no "the seed lecture");
- the front page and the README's status table agree with which chapters are written.

Usage: check_book.py BUILD/book/html
"""

from __future__ import annotations

import html as htmllib
import pathlib
import re
import shutil
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import grbd_exercises as gx  # noqa: E402

# The chapter pages, from the chapter folders (chapters/NN-topic -> chNN_topic.html).
CHAPTERS = ["ch" + folder.name.replace("-", "_")
            for folder in sorted(ROOT.glob("chapters/[0-9][0-9]-*")) if (folder / "chapter.md").exists()]
# Chapters that are written (not only an outline): they must quote code and show figures.
WRITTEN = ["ch01_kinematics", "ch02_rigid_bodies", "ch03_smooth_references", "ch04_collision",
           "ch05_contact_laws", "ch06_moreau_timestepping", "ch07_simulation_framework",
           "ch08_parallel_chute_flow"]
RESOURCE = re.compile(r'<(?:script|img|link|object)\b[^>]*?\b(?:src|href|data)="([^"]+)"', re.I)
# MathJax files the book's configuration loads (the rest is loaded on demand by these).
MATHJAX_FILES = ["MathJax.js", "jax/input/TeX/config.js", "jax/input/TeX/jax.js",
                 "jax/output/HTML-CSS/config.js", "jax/output/HTML-CSS/jax.js",
                 "jax/output/HTML-CSS/fonts/TeX/fontdata.js", "jax/element/mml/jax.js",
                 "extensions/tex2jax.js", "extensions/TeX/AMSmath.js",
                 "extensions/TeX/AMSsymbols.js", "extensions/MathMenu.js",
                 "extensions/MathZoom.js", "fonts/HTML-CSS/TeX/woff/MathJax_Main-Regular.woff"]
SNIPPET_MARKER = re.compile(r"^\s*//[/!]?\s*\[(?P<name>[^\]]+)\]\s*$")
SEED = re.compile(r"\bthe seed\b|\bseed's\b|\bseed lectures?\b", re.I)


def visible_text(content: str) -> str:
    """The prose of a page: no scripts, styles, code, fragments, mathematics or tags."""
    text = re.sub(r"<(script|style|pre|code)\b.*?</\1>", " ", content, flags=re.S | re.I)
    text = re.sub(r'<div class="fragment">.*?</div><!-- fragment -->', " ", text, flags=re.S)
    text = re.sub(r"<[^>]+>", " ", text)
    text = htmllib.unescape(text)
    text = re.sub(r"\\\(.*?\\\)", " ", text, flags=re.S)
    text = re.sub(r"\\\[.*?\\\]", " ", text, flags=re.S)
    text = re.sub(r"\\begin\{(\w+\*?)\}.*?\\end\{\1\}", " ", text, flags=re.S)
    return text


def snippet_markers() -> set[str]:
    """Every snippet marker name used in the sources the book quotes."""
    names = set()
    for folder in ("lib", "solutions", "chapters"):
        for path in (ROOT / folder).rglob("*"):
            if path.suffix in (".hpp", ".cpp", ".h") and path.is_file():
                for line in path.read_text(encoding="utf-8", errors="replace").splitlines():
                    m = SNIPPET_MARKER.match(line)
                    if m:
                        names.add(m.group("name"))
    return names


def check_navigation(html: pathlib.Path, problems: list[str]) -> None:
    index = (html / "index.html").read_text(encoding="utf-8")
    positions = [index.find(f'href="{c}.html"') for c in CHAPTERS]
    for chapter, pos in zip(CHAPTERS, positions):
        if pos < 0:
            problems.append(f"index.html does not link chapter page {chapter}.html")
        if not (html / f"{chapter}.html").exists():
            problems.append(f"chapter page {chapter}.html is missing")
    if all(p >= 0 for p in positions) and positions != sorted(positions):
        problems.append("index.html lists the chapters out of order")

    pages = html / "pages.html"
    listed = re.findall(r'href="(ch\d\d_\w+|bibliography)\.html"',
                        pages.read_text(encoding="utf-8") if pages.exists() else "")
    if [p for p in listed if p in CHAPTERS] != CHAPTERS:
        problems.append(f"the Chapters page (pages.html) lists {listed}, expected the chapters "
                        "in order")
    if "bibliography" not in listed:
        problems.append("the Chapters page (pages.html) does not list the bibliography")

    tree = (html / "navtreedata.js").read_text(encoding="utf-8")
    for page in CHAPTERS + ["bibliography"]:
        if f'"{page}.html", ' not in tree:
            problems.append(f"the sidebar tree (navtreedata.js) has no entry for {page}.html")

    order = CHAPTERS + ["bibliography"]
    for i, chapter in enumerate(CHAPTERS):
        path = html / f"{chapter}.html"
        if not path.exists():
            continue
        content = path.read_text(encoding="utf-8")
        prev = "index" if i == 0 else order[i - 1]
        for where in ("top", "bottom"):
            m = re.search(rf'<div class="grbd-nav grbd-nav-{where}">(.*?)</div>', content, re.S)
            if not m:
                problems.append(f"{chapter}.html has no previous/next links at the {where}")
                continue
            links = re.findall(r'href="([\w.]+)\.html"', m.group(1))
            if links != [prev, "index", order[i + 1]]:
                problems.append(f"{chapter}.html: the {where} links lead to {links}, expected "
                                f"{[prev, 'index', order[i + 1]]}")


def check_mathjax(html: pathlib.Path, problems: list[str]) -> None:
    mathjax = html / "mathjax"
    if mathjax.is_symlink() or not mathjax.is_dir():
        problems.append(f"{mathjax} must be a folder of the book, not a link")
    links = [p for p in html.rglob("*") if p.is_symlink()]
    for link in links[:5]:
        problems.append(f"{link.relative_to(html)} is a symbolic link: a copied book loses it")
    # Copy the book as a user would (links stay links) and look for MathJax in the copy.
    with tempfile.TemporaryDirectory() as tmp:
        copy = pathlib.Path(tmp) / "book"
        shutil.copytree(html / "mathjax", copy / "mathjax", symlinks=True)
        for name in MATHJAX_FILES:
            if not (copy / "mathjax" / name).is_file():
                problems.append(f"a copy of the book lacks mathjax/{name}")
    size = sum(p.stat().st_size for p in mathjax.rglob("*") if p.is_file()) if mathjax.is_dir() \
        else 0
    if size > 8e6:
        problems.append(f"the book's MathJax takes {size / 1e6:.1f} MB: copy only what it uses")


def check_figures(chapter: str, content: str, problems: list[str]) -> None:
    number = int(chapter[2:4])
    captions = re.findall(r'<div class="image">.*?<div class="caption">\s*(.*?)</div>', content,
                          re.S)
    if chapter in WRITTEN and not captions:
        problems.append(f"{chapter}.html shows no figure")
    for k, caption in enumerate(captions, start=1):
        if not caption.startswith(f"Figure {number}.{k}: "):
            problems.append(f"{chapter}.html: figure {k} is captioned '{caption[:40]}…', "
                            f"expected 'Figure {number}.{k}: …'")


def check_exercise_titles(chapter: str, content: str, problems: list[str]) -> None:
    number = int(chapter[2:4])
    chapter_dirs = [d for d in gx.chapter_dirs(ROOT) if int(d[:2]) == number]
    expected = {ex.id: ex.title for d in chapter_dirs for ex in gx.exercises_of(d, ROOT)}
    found = {}
    for heading in re.findall(r"<h[2-4]>.*?</h[2-4]>", content, re.S):
        text = htmllib.unescape(re.sub(r"<[^>]+>", "", heading)).strip()
        m = re.match(r"Exercise (\d+\.\d+): (.*)$", text)
        if m:
            found[m.group(1)] = m.group(2).strip()
    for ex_id, title in expected.items():
        if ex_id not in found:
            problems.append(f"{chapter}.html has no heading 'Exercise {ex_id}: {title}'")
        elif found[ex_id] != title:
            problems.append(f"{chapter}.html titles Exercise {ex_id} '{found[ex_id]}', but "
                            f"solutions/ titles it '{title}'")


def check_status(problems: list[str]) -> None:
    """The book's front page (book/index.md) and the README's status table say which chapters are
    written: a written chapter is not called an outline or planned there, and a chapter called an
    outline has no sections yet (else it is written and belongs in WRITTEN)."""
    index = (ROOT / "book" / "index.md").read_text(encoding="utf-8")
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    for chapter in CHAPTERS:
        number = int(chapter[2:4])
        entry = re.search(rf"^{number}\. \\ref {chapter}\b.*(?:\n   .*)*", index, re.M)
        row = re.search(rf"^\| {number} [^|]*\|[^|]*\|(?P<state>[^|]*)\|", readme, re.M)
        folder = next(ROOT.glob(f"chapters/{chapter[2:4]}-*/chapter.md"), None)
        sections = len(re.findall(r"^## ", folder.read_text(encoding="utf-8"), re.M)) \
            if folder else 0
        if chapter in WRITTEN:
            if entry and re.search(r"outline|planned", entry.group(0)):
                problems.append(f"book/index.md calls the written chapter {chapter} an outline or "
                                "planned")
            if row and "outline" in row.group("state"):
                problems.append(f"README.md's status table calls the written chapter {chapter} an "
                                "outline")
        elif sections > 1:
            problems.append(f"{chapter} has {sections} sections but is treated as an outline: add "
                            "it to WRITTEN in tests/book/check_book.py (and say so in book/index.md "
                            "and the README)")


def main() -> int:
    html = pathlib.Path(sys.argv[1])
    problems: list[str] = []
    if not (html / "index.html").exists():
        print(f"book: {html / 'index.html'} does not exist")
        return 1
    check_navigation(html, problems)
    check_mathjax(html, problems)
    check_status(problems)

    markers = snippet_markers()
    pages = sorted(html.glob("*.html"))
    for page in pages:
        content = page.read_text(encoding="utf-8", errors="replace")
        for ref in RESOURCE.findall(content):
            if re.match(r"^(https?:)?//", ref):
                problems.append(f"{page.name} loads {ref} from the network")
            elif not ref.startswith(("#", "data:", "javascript:")):
                target = (html / ref.split("#")[0].split("?")[0])
                if not target.exists():
                    problems.append(f"{page.name} refers to {ref}, which does not exist")
        text = visible_text(content)
        for name in sorted(markers):
            if f"[{name}]" in text:
                problems.append(f"{page.name}: the snippet marker '[{name}]' shows as text "
                                "(Doxygen took it for documentation)")
        for pattern, what in ((r"\*\*", "**"), (r"`", "`"), (r"\\f[$\[\]{}]", "\\f$"),
                              (r"BOOK ERROR", "BOOK ERROR")):
            for m in re.finditer(pattern, text):
                context = " ".join(text[max(0, m.start() - 40):m.end() + 40].split())
                problems.append(f"{page.name}: unrendered '{what}' in the text: …{context}…")
        m = SEED.search(text)
        if m:
            problems.append(f"{page.name}: '{m.group(0)}' names no source a reader can find")

    for chapter in CHAPTERS:
        page = html / f"{chapter}.html"
        if not page.exists():
            continue
        content = page.read_text(encoding="utf-8")
        if 'src="mathjax/MathJax.js' not in content:
            problems.append(f"{page.name} does not load the local MathJax")
        if "autoNumber" not in content:
            problems.append(f"{page.name} does not number its equations (MathJax autoNumber)")
        check_figures(chapter, content, problems)
        if chapter in WRITTEN:
            if 'class="fragment"' not in content:
                problems.append(f"{page.name} quotes no code (no \\snippet fragment)")
            if "\\(" not in content and "\\[" not in content:
                problems.append(f"{page.name} contains no mathematics")
            check_exercise_titles(chapter, content, problems)
    for problem in problems:
        print(f"book: {problem}")
    print(f"book: {len(pages)} pages checked, {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
