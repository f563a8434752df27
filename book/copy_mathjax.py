#!/usr/bin/env python3
"""Copy the parts of MathJax 2 that the book uses into the book's HTML tree.

    copy_mathjax.py <system MathJax folder> <book html folder>

The book must render its mathematics offline and keep doing so when its folder is copied to a web
server or a USB stick, so it holds real files, never links to the system's MathJax: the TeX input,
the HTML-CSS output with the TeX web fonts (woff, and otf for old browsers), the MathML element
jax, and the extensions the configuration loads or MathJax loads on demand. Debian's
libjs-mathjax links the fonts to fonts-mathjax; they are copied as files. About 2.3 MB in all,
against 54 MB for the whole of MathJax. A second run copies only what changed.
"""

from __future__ import annotations

import filecmp
import pathlib
import shutil
import sys

# Folders and files of MathJax, relative to its root, that the book needs.
PARTS = [
    "MathJax.js",
    "jax/input/TeX",
    "jax/element/mml",
    "jax/output/HTML-CSS/jax.js",
    "jax/output/HTML-CSS/config.js",
    "jax/output/HTML-CSS/imageFonts.js",
    "jax/output/HTML-CSS/autoload",
    "jax/output/HTML-CSS/fonts/TeX",
    "fonts/HTML-CSS/TeX/woff",
    "fonts/HTML-CSS/TeX/otf",
    "extensions/tex2jax.js",
    "extensions/MathEvents.js",
    "extensions/MathMenu.js",
    "extensions/MathZoom.js",
    "extensions/FontWarnings.js",
    "extensions/HelpDialog.js",
    "extensions/TeX",
    "extensions/HTML-CSS",
    "localization/en",
]


def copy_file(source: pathlib.Path, target: pathlib.Path) -> None:
    if target.is_symlink():
        target.unlink()
    if target.is_file() and filecmp.cmp(source, target, shallow=False):
        return
    target.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(source, target)  # follows links: the book gets the file itself


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    source_root = pathlib.Path(sys.argv[1])
    target_root = pathlib.Path(sys.argv[2]) / "mathjax"
    if target_root.is_symlink():  # books built before the MathJax copy linked the whole folder
        target_root.unlink()
    missing = []
    for part in PARTS:
        source = source_root / part
        if source.is_file():
            copy_file(source, target_root / part)
        elif source.is_dir():
            for path in sorted(source.rglob("*")):
                if path.is_file():
                    copy_file(path, target_root / path.relative_to(source_root))
        else:
            missing.append(str(source))
    if missing:
        print("copy_mathjax.py: the local MathJax lacks " + ", ".join(missing)
              + " (Debian packages libjs-mathjax and fonts-mathjax)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
