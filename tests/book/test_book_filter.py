"""Tests of the book's Doxygen filter (book/book_filter.py): optional sections, figure numbers,
snippets that would show an exercise's solution, numbers taken from the demos, tables that claim a
demo's output but hold numbers written by hand, and the formulas of captions.

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


class Experiments(unittest.TestCase):
    """The experiments (demos that run for minutes, README command (1) only) stand in where this
    build has not run them; nothing else may be missing."""

    def test_an_experiment_not_run_stands_in_and_one_that_ran_is_shown(self):
        folder = tempfile.TemporaryDirectory(prefix="grbd_book_experiments_")
        self.addCleanup(folder.cleanup)
        figures = pathlib.Path(folder.name)
        page = PAGE.split("\n")[0] + "\n\n" + "\n".join([
            '\\image html ch07_heap.svg "A heap."',
            "angle \\demo{ch07_heap/values.txt#angle} degrees",
            '\\image html ch07_quick.svg "A quick one."',
            "\\demo{ch07_quick/values.txt#n}"])
        out = book_filter.filter_chapter(pathlib.Path("chapter.md"), page, set(), figures,
                                         {"ch07_heap"}).split("\n")
        self.assertIn("\\image html standin_ch07_heap.svg", out[2])
        self.assertIn("not drawn by this build", out[2])
        self.assertEqual(out[3], "angle ? degrees")
        self.assertIn("\\image html ch07_quick.svg", out[4])  # Doxygen reports it missing
        self.assertIn("BOOK ERROR: \\demo{ch07_quick/values.txt#n}: no file", out[5])
        # Once the experiment has run, its own figure and values.
        (figures / "ch07_heap.svg").write_text("<svg/>")
        (figures / "ch07_heap").mkdir()
        (figures / "ch07_heap" / "values.txt").write_text("angle = 22.9\n")
        out = book_filter.filter_chapter(pathlib.Path("chapter.md"), page, set(), figures,
                                         {"ch07_heap"}).split("\n")
        self.assertIn("\\image html ch07_heap.svg", out[2])
        self.assertEqual(out[3], "angle 22.9 degrees")
        # A key the experiment did not write is an error even so.
        (figures / "ch07_heap" / "values.txt").write_text("slope = 0.4\n")
        out = book_filter.filter_chapter(pathlib.Path("chapter.md"), page, set(), figures,
                                         {"ch07_heap"}).split("\n")
        self.assertIn("BOOK ERROR: \\demo{ch07_heap/values.txt#angle}: the demo wrote no value",
                      out[3])


class DemoTables(unittest.TestCase):
    """A table introduced as a demo's output holds no number written by hand (issue: chapters 1-5
    copied the demos' tables into the text, and they drifted)."""

    TABLE = ["| problem | SOR | JOR | APGD |", "|---|---|---|---|",
             "| frictional pile, cold | <a> | <b> | <c> |",
             "| deep frictionless pile | <d> | > 3000 (\\f$2.9\\cdot10^{-3}\\f$) | 273 |"]

    def filtered(self, introduction, cells, figures=None):
        rows = list(self.TABLE)
        for name, cell in cells.items():
            rows = [row.replace(f"<{name}>", cell) for row in rows]
        page = PAGE.split("\n")[0] + "\n\n" + "\n".join(introduction + [""] + rows)
        return book_filter.filter_chapter(pathlib.Path("chapter.md"), page, set(),
                                          figures).split("\n")

    def figures(self):
        folder = tempfile.TemporaryDirectory(prefix="grbd_book_tables_")
        self.addCleanup(folder.cleanup)
        figures = pathlib.Path(folder.name)
        (figures / "ch05_demo").mkdir()
        (figures / "ch05_demo" / "values.txt").write_text(
            "cold.SOR = 618\ncold.JOR = 2425\ncold.APGD = 487\ndeep.SOR = 1653\n"
            "deep.JOR = > 3000 (\\f$2.9\\cdot10^{-3}\\f$)\ndeep.APGD = 273\n")
        return figures

    def test_a_table_that_claims_a_demos_output_with_literal_numbers_is_a_book_error(self):
        literal = {"a": "618", "b": "2425", "c": "487", "d": "1653"}
        for introduction in (["Iterations to the tolerance (from `convergence.txt`):"],
                             ["On that machine the demo measured the numbers below.", "",
                              "All times in nanoseconds per sphere:"],
                             ["The table is the demo's output, read when the book is built:"]):
            with self.subTest(introduction=introduction):
                out = self.filtered(introduction, literal)
                errors = [line for line in out if line.startswith("BOOK ERROR")]
                self.assertEqual(len(errors), 2, out)  # both body rows, each in place of its row
                self.assertIn("says it is a demo's output", errors[0])
                self.assertIn("its cell '618' is a number written by hand", errors[0])
                self.assertIn("its cell '1653'", errors[1])
                first_row = 2 + len(introduction) + 1 + 2  # title, blank, text, blank, header
                self.assertTrue(out[first_row].startswith("BOOK ERROR"), out)  # same line numbers
                self.assertTrue(out[first_row + 1].startswith("BOOK ERROR"), out)
                self.assertEqual(out[first_row - 1], "|---|---|---|---|")

    def test_the_same_table_with_the_demos_values_passes(self):
        demo = {k: f"\\demo{{ch05_demo/values.txt#{key}}}" for k, key in
                (("a", "cold.SOR"), ("b", "cold.JOR"), ("c", "cold.APGD"), ("d", "deep.SOR"))}
        self.TABLE = self.TABLE[:3] + [
            "| deep frictionless pile | <d> | \\demo{ch05_demo/values.txt#deep.JOR} | "
            "\\demo{ch05_demo/values.txt#deep.APGD} |"]
        out = self.filtered(["Iterations to the tolerance (from `convergence.txt`):"], demo,
                            self.figures())
        self.assertFalse([line for line in out if "BOOK ERROR" in line], out)
        self.assertIn("| frictional pile, cold | 618 | 2425 | 487 |", out)
        self.assertIn("| deep frictionless pile | 1653 | > 3000 (\\f$2.9\\cdot10^{-3}\\f$) | 273 |",
                      out)

    def test_a_benchmark_measured_once_by_hand_and_a_table_without_a_claim_pass(self):
        literal = {"a": "618", "b": "2425", "c": "487", "d": "1653"}
        for introduction in (["Google Benchmark medians, measured once by hand with",
                              "`build/bin/benchmarks/ch05_bench_sor`; the iterations are the demo's",
                              "output, read when the book is built:"],
                             ["The relaxation has a sweet spot:"]):
            with self.subTest(introduction=introduction):
                out = self.filtered(introduction, literal)
                self.assertFalse([line for line in out if "BOOK ERROR" in line], out)

    def test_what_counts_as_a_literal_number(self):
        for cell in ("618", "> 3000", "15 700", "\\f$2.74\\cdot10^{-3}\\f$ rad", "1.0e-08",
                     "11.2 ± 0.2°", "13.5 ms", "0.022 %", "**4.7e7**", "\\f$-0.616\\f$",
                     "> 3000 (\\f$2.9\\cdot10^{-3}\\f$)"):
            self.assertTrue(book_filter.is_literal_number(cell), cell)
        for cell in ("\\demo{a/values.txt#b}", "SOR-AC", "doubled after 11 turns", "—",
                     "box 0.16 × 0.08 × 0.02 m", "\\f$10^{-3}\\f$ rad, by \\demo{a/values.txt#b}"):
            self.assertFalse(book_filter.is_literal_number(cell), cell)

    def test_the_chapters_pass(self):
        for chapter in sorted(ROOT.glob("chapters/[0-9][0-9]-*/chapter.md")):
            lines = chapter.read_text(encoding="utf-8").split("\n")
            self.assertEqual(book_filter.demo_table_problems(lines), {}, chapter)


class Captions(unittest.TestCase):
    """A caption's formulas are typeset by MathJax like the text's; plain-text subscripts are
    refused."""

    def caption_line(self, caption):
        page = PAGE.split("\n")[0] + "\n\n" + f'\\image html ball.svg "{caption}"'
        return book_filter.filter_chapter(pathlib.Path("chapter.md"), page, set()).split("\n")[2]

    def test_a_formula_is_written_for_mathjax_with_backslashes_doubled(self):
        line = self.caption_line("A ball, \\f$\\varepsilon_N = 0.8\\f$, \\f$\\Delta t\\f$ = 1 ms.")
        self.assertEqual(line, '\\anchor fig_ball \\image html ball.svg "Figure 7.1: A ball, '
                               '\\\\(\\\\varepsilon_N = 0.8\\\\), \\\\(\\\\Delta t\\\\) = 1 ms."')

    def test_a_plain_text_subscript_is_a_book_error(self):
        for caption, subscript in (("A ball, ε_N = 0.8.", "ε_N"), ("ω2 flips.", "ω2"),
                                   ("γ = W_aᵀu_a.", "W_a"), ("with A_IK = R(p).", "A_I")):
            with self.subTest(caption=caption):
                line = self.caption_line(caption)
                self.assertIn(f"BOOK ERROR: the caption of ball.svg writes the subscript "
                              f"'{subscript}' as plain text", line)

    def test_names_of_code_are_not_subscripts(self):
        line = self.caption_line("The pairs of find_pairs and tangent_basis(n), drawn by "
                                 "paraview_spheres.py from ch07_janssen; \\f$\\omega_2\\f$.")
        self.assertNotIn("BOOK ERROR", line)

    def test_no_chapter_has_a_plain_text_subscript_in_a_caption(self):
        for chapter in sorted(ROOT.glob("chapters/[0-9][0-9]-*/chapter.md")):
            out = book_filter.filter_chapter(chapter, chapter.read_text(encoding="utf-8"),
                                             {"paraview"})
            self.assertEqual([line for line in out.split("\n") if "as plain text" in line], [],
                             chapter)


if __name__ == "__main__":
    unittest.main()
