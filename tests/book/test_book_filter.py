"""Tests of the book's Doxygen filter (book/book_filter.py): optional sections and figure numbers.

The filter resolves `\\if NAME` ... `\\else` ... `\\endif` itself, so that a figure inside a section
that the build left out takes no number; these tests check that against hand-counted pages.
"""

import pathlib
import sys
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "book"))
import book_filter  # noqa: E402

PAGE = "\n".join([
    "# Chapter 7: The simulation framework {#ch07_simulation_framework}",  # 1
    "",
    "Text before.",
    "\\if paraview",
    '\\image html shot.png "A screenshot."',                              # 5
    "\\else",
    "No screenshot in this build.",
    "\\endif",
    "```sh",
    "\\if this is code, not a directive",                                  # 10
    "```",
    '\\image html plot.svg "A plot."',
    "See \\figref{plot}.",
])


def lines_of(sections):
    text = book_filter.filter_chapter(pathlib.Path("chapter.md"), PAGE, sections)
    return text.split("\n")


class OptionalSections(unittest.TestCase):
    def test_an_enabled_section_is_kept_and_numbered_first(self):
        out = lines_of({"paraview"})
        self.assertIn('"Figure 7.1: A screenshot."', out[4])
        self.assertEqual(out[6], "")  # the \else branch is dropped
        self.assertIn('"Figure 7.2: A plot."', out[11])
        self.assertIn('"Figure 7.2"', out[12])
        self.assertEqual(out[9], "\\if this is code, not a directive")

    def test_a_disabled_section_takes_no_figure_number(self):
        out = lines_of(set())
        self.assertEqual(out[4], "")
        self.assertEqual(out[6], "No screenshot in this build.")
        self.assertIn('"Figure 7.1: A plot."', out[11])
        self.assertIn('"Figure 7.1"', out[12])

    def test_line_numbers_are_kept(self):
        # Doxygen's warnings must point at the source's lines: one line out per line in (the
        # filter appends the navigation at the bottom only).
        for sections in (set(), {"paraview"}):
            out = lines_of(sections)
            self.assertEqual(out[2], "Text before.")
            self.assertEqual(out[10], "```")

    def test_an_unclosed_or_stray_directive_is_a_book_error(self):
        unclosed = book_filter.filter_chapter(pathlib.Path("chapter.md"),
                                              "\n".join(PAGE.split("\n")[:5]), set())
        self.assertIn("BOOK ERROR: an \\if block is not closed by \\endif", unclosed)
        stray = book_filter.filter_chapter(pathlib.Path("chapter.md"), PAGE + "\n\\endif", set())
        self.assertIn("BOOK ERROR: unmatched or malformed '\\endif'", stray)


if __name__ == "__main__":
    unittest.main()
