"""Tests of the book's Doxygen filter (book/book_filter.py): optional sections, figure numbers, and
snippets that would show an exercise's solution.

The filter resolves `\\if NAME` ... `\\else` ... `\\endif` itself, so that a figure inside a section
that the build left out takes no number; these tests check that against hand-counted pages.
"""

import pathlib
import sys
import tempfile
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


class ExerciseRegions(unittest.TestCase):
    """No snippet may print the inside of an exercise region: the book would give it away."""

    def page_with(self, snippet):
        return book_filter.filter_chapter(pathlib.Path("chapter.md"),
                                          PAGE.split("\n")[0] + "\n\n" + snippet, set())

    def test_a_snippet_that_holds_or_starts_inside_a_region_is_a_book_error(self):
        folder = tempfile.TemporaryDirectory(prefix="grbd_book_filter_")
        self.addCleanup(folder.cleanup)
        source = pathlib.Path(folder.name) / "source.cpp"  # absolute: ROOT / it is itself
        source.write_text("\n".join([
            "// [around]", "int f() {", "  // BEGIN EXERCISE 9.1: f", "  return 1;",
            "  // END EXERCISE 9.1", "}", "// [around]",
            "// BEGIN EXERCISE 9.2: g", "// [within]", "int g() { return 2; }", "// [within]",
            "// END EXERCISE 9.2",
            "// [outside]", "int h();", "// [outside]"]), encoding="utf-8")
        name = source.as_posix()
        for tag, exercise in (("around", "9.1"), ("within", "9.2")):
            out = self.page_with(f"\\snippet {name} {tag}")
            self.assertIn(f"BOOK ERROR: \\snippet {name} {tag} shows the region of Exercise "
                          f"{exercise}", out)
        self.assertNotIn("BOOK ERROR", self.page_with(f"\\snippet {name} outside"))

    def test_no_chapter_shows_an_exercise_region(self):
        for chapter in sorted(ROOT.glob("chapters/[0-9][0-9]-*/chapter.md")):
            out = book_filter.filter_chapter(chapter, chapter.read_text(encoding="utf-8"),
                                             {"paraview"})
            self.assertNotIn("shows the region of Exercise", out, chapter)


class DemoValues(unittest.TestCase):
    """A number a demo computes reaches the page from the demo's output, never by hand."""

    def test_a_value_is_read_from_the_demos_file_and_a_missing_one_is_a_book_error(self):
        folder = tempfile.TemporaryDirectory(prefix="grbd_book_values_")
        self.addCleanup(folder.cleanup)
        figures = pathlib.Path(folder.name)
        (figures / "ch07_demo").mkdir()
        (figures / "ch07_demo" / "values.txt").write_text("pile.iterations = 450\n"
                                                         "residual = 5.2\\cdot10^{-7}\n")
        page = PAGE.split("\n")[0] + "\n\n" + "\n".join([
            "| \\demo{ch07_demo/values.txt#pile.iterations} | \\f$\\demo{ch07_demo/values.txt#residual}\\f$ |",
            "\\demo{ch07_demo/values.txt#nothing}",
            "\\demo{ch07_none/values.txt#pile.iterations}"])
        out = book_filter.filter_chapter(pathlib.Path("chapter.md"), page, set(), figures)
        lines = out.split("\n")
        self.assertEqual(lines[2], "| 450 | \\f$5.2\\cdot10^{-7}\\f$ |")
        self.assertIn("BOOK ERROR: \\demo{ch07_demo/values.txt#nothing}: the demo wrote no value",
                      lines[3])
        self.assertIn("BOOK ERROR: \\demo{ch07_none/values.txt#pile.iterations}: no file",
                      lines[4])
        self.assertEqual(len(lines[:5]), 5)  # one line out per line in


if __name__ == "__main__":
    unittest.main()
