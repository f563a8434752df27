#!/usr/bin/env python3
"""Checks on the built book (build/book/html) that a reader would otherwise find by hand:

- the main page lists the chapters in their order, and every chapter page exists;
- the mathematics is typeset by the local MathJax: the pages load mathjax/MathJax.js from the
  book's own tree (which resolves to a real file), never from the network, and the configured
  extensions exist;
- every image and script a page refers to exists in the tree, and no page loads anything from the
  network;
- written chapters quote code (\\snippet fragments) and show their figures.

Usage: check_book.py BUILD/book/html
"""

import pathlib
import re
import sys

CHAPTERS = ["ch01_kinematics", "ch02_rigid_bodies", "ch03_smooth_references", "ch04_collision",
            "ch05_contact_laws", "ch06_moreau_timestepping", "ch07_simulation_framework",
            "ch08_parallel_chute_flow"]
# Chapters that are written (not only an outline): they must quote code and show figures.
WRITTEN = ["ch01_kinematics", "ch02_rigid_bodies", "ch03_smooth_references", "ch04_collision",
           "ch05_contact_laws"]
RESOURCE = re.compile(r'<(?:script|img|link)\b[^>]*?\b(?:src|href)="([^"]+)"', re.I)


def main() -> int:
    html = pathlib.Path(sys.argv[1])
    problems = []
    index = html / "index.html"
    if not index.exists():
        print(f"book: {index} does not exist")
        return 1
    text = index.read_text(encoding="utf-8")
    positions = [text.find(f'href="{c}.html"') for c in CHAPTERS]
    for chapter, pos in zip(CHAPTERS, positions):
        if pos < 0:
            problems.append(f"index.html does not link chapter page {chapter}.html")
        if not (html / f"{chapter}.html").exists():
            problems.append(f"chapter page {chapter}.html is missing")
    if all(p >= 0 for p in positions) and positions != sorted(positions):
        problems.append("index.html lists the chapters out of order")

    mathjax = html / "mathjax" / "MathJax.js"
    if not mathjax.resolve().is_file():
        problems.append(f"{mathjax} does not resolve to the local MathJax")
    for ext in ("TeX/AMSmath.js", "TeX/AMSsymbols.js"):
        if not (html / "mathjax" / "extensions" / ext).resolve().is_file():
            problems.append(f"MathJax extension {ext} is missing from the local copy")

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
    for chapter in CHAPTERS:
        page = html / f"{chapter}.html"
        if not page.exists():
            continue
        content = page.read_text(encoding="utf-8")
        if 'src="mathjax/MathJax.js' not in content:
            problems.append(f"{page.name} does not load the local MathJax")
        if chapter in WRITTEN:
            if 'class="fragment"' not in content:
                problems.append(f"{page.name} quotes no code (no \\snippet fragment)")
            if not re.search(r'<img[^>]+src="[^"]+\.svg"', content):
                problems.append(f"{page.name} shows no figure")
            if "\\(" not in content and "\\[" not in content:
                problems.append(f"{page.name} contains no mathematics")
    for problem in problems:
        print(f"book: {problem}")
    print(f"book: {len(pages)} pages checked, {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
