#!/usr/bin/env python3
"""Chapter 7: the `grbd` command line under bad input, as a fault campaign found it.

Run by CTest as `test_cli_faults.py <grbd executable> <test scene>`. Each test works in its own
temporary folder with real processes. The rules under test (chapter 7, "Files, limits and
failures"): no result is ever lost (nothing is truncated or overwritten before every check passed),
a blow-up is an error and not data, and every refusal comes before the run and names the right
file.
"""

import os
import random
import resource
import shutil
import signal
import subprocess
import sys
import time
import unittest

import h5py
import numpy as np

import test_cli
from test_cli import Scratch, run

SCENE = None


def text_of(path):
    with open(path, "rb") as f:
        return f.read()


def scene_text(body, extra=""):
    """A small scene of one list group, with `body` lines added to the group."""
    return ("[simulation]\ndt = 1e-3\nend_time = 3e-3\n\n[[material]]\nname = \"glass\"\n\n"
            "[default_contact]\nmu = 0.5\n\n[[bodies]]\nradius = 0.01\ndensity = 2500.0\n"
            "material = \"glass\"\n" + body + "\n" + extra)


class Faults(Scratch):
    """A test folder with a helper to write the files a case needs."""

    def write(self, name, text):
        path = self.path(name)
        with open(path, "w") as f:
            f.write(text)
        return path

    def chute_with(self, name, old, new):
        """The test scene with one piece of text replaced."""
        with open(SCENE) as f:
            text = f.read()
        self.assertIn(old, text)
        return self.write(name, text.replace(old, new))


class NoResultIsLost(Faults):
    """Classes 1-3: the output, its XDMF, the checkpoint, the scene and other inputs."""

    def first_run(self, out="out.h5", ckpt="out.ckpt.h5", end="0.05"):
        result = run("run", SCENE, "-q", "-o", self.path(out), "-c", self.path(ckpt),
                     "--end-time", end)
        self.assertEqual(result.returncode, 0, result.stderr)
        return self.path(out), self.path(ckpt)

    def snapshot(self):
        return {name: text_of(self.path(name)) for name in sorted(os.listdir(self.dir))
                if os.path.isfile(self.path(name))}

    def test_a_second_run_onto_an_output_in_use_is_refused_without_touching_it(self):
        reference = self.reference(1.0)
        out = self.path("same.h5")
        first = subprocess.Popen([test_cli.GRBD, "run", SCENE, "-q", "-o", out, "-c",
                                  self.path("a.ckpt.h5"), "--end-time", "1.0"],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        deadline = time.time() + 60
        while not (os.path.exists(out) and os.path.getsize(out) > 0):
            self.assertIsNone(first.poll(), "the first run ended early")
            self.assertLess(time.time(), deadline)
            time.sleep(0.01)
        for extra in ([], ["--force"]):
            second = run("run", SCENE, "-q", "-o", out, "-c", self.path("b.ckpt.h5"),
                         "--end-time", "1.0", *extra)
            self.assertEqual(second.returncode, 3, second.stderr)
            self.assertIn("same.h5", second.stderr)
        self.assertIn("is in use", second.stderr)
        self.assertFalse(os.path.exists(self.path("b.ckpt.h5")))
        stdout, stderr = first.communicate(timeout=300)
        self.assertEqual(first.returncode, 0, stderr)
        self.assertSameOutput(reference, out)

    def test_files_that_coincide_are_refused_whatever_their_spelling(self):
        out, ckpt = self.first_run()
        os.link(out, self.path("hard.h5"))
        os.symlink(out, self.path("soft.h5"))
        shutil.copy(SCENE, self.path("scene.toml"))
        scene = self.path("scene.toml")
        os.mkdir(self.path("sub"))
        here = os.getcwd()
        os.chdir(self.path("sub"))
        try:
            cases = [
                ["-o", self.path("new.h5"), "-c", "../new.h5"],        # other spelling
                ["-o", "fresh.h5", "-c", "./fresh.h5"],                 # relative, both new
                ["-o", self.path("new.h5"), "-c", self.path("new.xmf")],  # the XDMF
                ["-o", self.path("result.xmf"), "-c", self.path("r.ckpt.h5")],  # its own XDMF
                ["-o", scene, "-c", self.path("r.ckpt.h5")],            # the scene itself
                ["-o", self.path("n.h5"), "-c", scene],
                ["-o", self.path("k.h5.tmp"), "-c", self.path("k.h5")],  # its temporary
                ["-o", self.path("hard.h5"), "-c", self.path("c2.h5"), "-r", out],  # a hard link
                ["-o", self.path("soft.h5"), "-c", self.path("c2.h5"), "-r", out],  # a symlink
                ["-o", ckpt, "-c", self.path("c3.h5"), "-r", ckpt],     # output = restart
            ]
            before = self.snapshot()
            for args in cases:
                result = run("run", scene, "-q", *args)
                self.assertEqual(result.returncode, 2, (args, result.stderr))
                self.assertRegex(result.stderr, "are the same file|it would be destroyed")
                self.assertEqual(self.snapshot(), before, args)
        finally:
            os.chdir(here)

    def test_a_fresh_run_does_not_replace_an_earlier_result_unless_forced(self):
        out, ckpt = self.first_run()
        for args in (["-o", out, "-c", self.path("other.ckpt.h5")],
                     ["-o", self.path("other.h5"), "-c", ckpt]):
            before = {p: text_of(p) for p in (out, ckpt, out[:-3] + ".xmf")}
            result = run("run", SCENE, "-q", *args, "--end-time", "0.01")
            self.assertEqual(result.returncode, 3, result.stderr)
            self.assertIn("exists already", result.stderr)
            self.assertIn("--force", result.stderr)
            self.assertEqual({p: text_of(p) for p in before}, before)
        result = run("run", SCENE, "-q", "-o", out, "-c", ckpt, "--end-time", "0.01", "--force")
        self.assertEqual(result.returncode, 0, result.stderr)
        with h5py.File(out, "r") as f:
            self.assertEqual(len(f["steps"]), 20)

    def test_a_restart_into_the_output_of_another_run_is_refused(self):
        other = self.chute_with("other.toml", "mu = 0.4", "mu = 0.1")
        theirs, _ = self.first_run("theirs.h5", "theirs.ckpt.h5")
        result = run("run", other, "-q", "-o", self.path("mine.h5"), "-c",
                     self.path("mine.ckpt.h5"), "--end-time", "0.025")
        self.assertEqual(result.returncode, 0, result.stderr)
        before = text_of(theirs)
        result = run("run", other, "-q", "-o", theirs, "-c", self.path("mine.ckpt.h5"),
                     "--restart", self.path("mine.ckpt.h5"))
        self.assertEqual(result.returncode, 3, result.stderr)
        self.assertIn("theirs.h5: belongs to another run", result.stderr)
        self.assertEqual(text_of(theirs), before)

    def test_a_nul_in_a_file_name_is_refused(self):
        victim = self.write("victim.txt", "keep me")
        scene = self.write("nul.toml", scene_text('positions = [[0.0, 0.0, 0.0]]',
                                                  '[output]\nfile = "victim.txt\\u0000.h5"\n'))
        result = run("run", scene, "-q", cwd=self.dir)
        self.assertEqual(result.returncode, 3, result.stderr)
        self.assertIn("output.file: expected a file name without NUL characters, found the "
                      'string "victim.txt\\u0000.h5"', result.stderr)
        self.assertNotIn("\0", result.stderr)
        self.assertEqual(text_of(victim), b"keep me")

    def test_fclib_never_destroys_a_problem_or_an_earlier_csv(self):
        problem = self.path("problem.hdf5")
        shutil.copy(os.path.join(test_cli.FCLIB_DATA, "Spheres-i099-356-679.hdf5"), problem)
        before = text_of(problem)
        for csv in (problem, os.path.join(self.dir, ".", "problem.hdf5")):
            result = run("fclib", problem, "--max-iterations", "5", "--csv", csv)
            self.assertEqual(result.returncode, 2, result.stderr)
            self.assertIn("it would be destroyed", result.stderr)
        self.assertEqual(text_of(problem), before)
        keep = self.write("keep.csv", "an earlier table\n")
        result = run("fclib", problem, SCENE, "--max-iterations", "5", "--csv", keep)
        self.assertEqual(result.returncode, 3, result.stderr)
        self.assertEqual(text_of(keep), b"an earlier table\n")
        self.assertEqual(sorted(os.listdir(self.dir)), ["keep.csv", "problem.hdf5"])


class BlowUpsAreErrors(Faults):
    """Class 4: a step that leaves a non-finite state stops the run; class 5: huge rates."""

    def run_scene(self, text, *args):
        scene = self.write("s.toml", text)
        return run("run", scene, "-q", "-o", self.path("o.h5"), "-c", self.path("c.h5"), *args)

    def test_a_blow_up_stops_the_run_naming_step_time_and_body(self):
        for velocity in ('angular_velocity = [1e308, 1e308, 0.0]',
                         'velocity = [1e308, 1e308, 0.0]'):
            result = self.run_scene(scene_text(velocity + "\npositions = [[0.0, 0.0, 0.0]]",
                                               "[output]\nevery = 1\n"), "--force")
            self.assertEqual(result.returncode, 1, result.stderr)
            self.assertIn("step 1 (t = 0.001 s): body 0 blew up",
                          result.stderr)
            with h5py.File(self.path("o.h5"), "r") as f:  # what was valid: the first record
                self.assertEqual(int(f["records"].attrs["count"]), 1)
                self.assertTrue(np.all(np.isfinite(f["records/000000/p"][()])))
            self.assertFalse(os.path.exists(self.path("c.h5")))  # no checkpoint of a blow-up

    def test_gravity_whose_square_overflows_is_refused(self):
        result = self.run_scene(scene_text("positions = [[0.0, 0.0, 0.0]]").replace(
            "end_time = 3e-3\n", "end_time = 3e-3\ngravity = [1e300, 1e300, 1e300]\n"))
        self.assertEqual(result.returncode, 3, result.stderr)
        self.assertIn("simulation.gravity: expected a vector of magnitude below", result.stderr)

    def test_a_silo_under_a_huge_gravity_stops_at_its_first_step(self):
        # Finite energies, but after one step the beads are 10¹⁴³ m out, where doubles are
        # 10¹²⁷ m apart: every bead would touch every other.
        scene = self.chute_with("s.toml", "gravity = [0.0, 0.0, -9.81]",
                                "gravity = [1e150, 1e150, 1e150]")
        result = run("run", scene, "-q", "-o", self.path("o.h5"), "-c", self.path("c.h5"))
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertRegex(result.stderr, r"step 1 \(t = 0\.0005\d* s\): body \d+ blew up")
        self.assertIn("more than 10¹² bounding radii from the origin", result.stderr)

    def test_an_inflow_rate_beyond_a_64_bit_count_fills_its_region(self):
        result = self.run_scene(scene_text(
            '[bodies.generator]\nkind = "inflow"\n'
            'region = { min = [0.0, 0.0, 0.0], max = [0.1, 0.1, 0.1] }\nrate = 1e23',
            "[output]\nevery = 1\n").replace("radius = 0.01\n", "radius = 0.005\n"))
        self.assertEqual(result.returncode, 0, result.stderr)
        with h5py.File(self.path("o.h5"), "r") as f:
            self.assertGreater(len(f["bodies"]), 100)  # 0 when the count overflowed


class RefusalsComeFirst(Faults):
    """Classes 6-8 and 11: refused before the first step, naming the right file."""

    def test_an_output_path_that_cannot_be_written_is_refused_before_the_run(self):
        os.mkdir(self.path("sub"))
        # A checkpoint only at the end of a long run: refused at once, or the test's time limit
        # ends it.
        scene = self.chute_with("s.toml", "every = 100", "every = 0")
        out, ckpt = self.path("o.h5"), self.path("c.h5")
        for args, message in ((["-o", out, "-c", self.path("nodir/c.h5")], "does not exist"),
                              (["-o", out, "-c", self.path("sub")], "it is a folder"),
                              (["-o", out, "-c", ""], 'expected a file name, found ""'),
                              (["-o", self.path("nodir/o.h5"), "-c", ckpt], "does not exist"),
                              (["-o", "/dev/null", "-c", ckpt], "not a regular file")):
            result = run("run", scene, "-q", *args, "--end-time", "100")
            self.assertEqual(result.returncode, 3, (args, result.stderr))
            self.assertIn(message, result.stderr)
            self.assertEqual(sorted(os.listdir(self.dir)), ["s.toml", "sub"], args)
            self.assertEqual(os.listdir(self.path("sub")), [])

    def test_end_time_obeys_the_rules_of_the_scene_key(self):
        out = self.write("out.h5", "an earlier file")
        for value, message in (("", "expected a decimal number"),
                               ("0x10", "expected a decimal number"),
                               ("inf", "expected a decimal number"),
                               ("1e300", "expected at most 10¹² steps"),
                               ("-1", "expected a time > 0")):
            result = run("run", SCENE, "-q", "-o", out, "--end-time", value, "--force")
            self.assertEqual(result.returncode, 2, (value, result.stderr))
            self.assertIn("--end-time: " + message, result.stderr)
            self.assertEqual(text_of(out), b"an earlier file")

    def test_what_is_not_a_regular_file_is_refused_at_once(self):
        os.mkfifo(self.path("fifo"))
        for args in (["validate", "/dev/zero"], ["validate", self.path("fifo")],
                     ["run", "/dev/zero", "-o", self.path("o.h5")],
                     ["info", self.path("fifo")],
                     ["run", SCENE, "-o", self.path("o.h5"), "-r", self.path("fifo")],
                     ["run", SCENE, "-o", self.path("o.h5"), "-r", "/dev/zero"]):
            result = subprocess.run([test_cli.GRBD, *args], capture_output=True, text=True,
                                    timeout=30)
            self.assertEqual(result.returncode, 3, (args, result.stderr))
            self.assertIn("is not a regular file", result.stderr)
        self.assertFalse(os.path.exists(self.path("o.h5")))

    def test_a_scene_larger_than_memory_is_refused_before_allocating(self):
        scene = self.write("big.toml", scene_text(
            '[bodies.generator]\nkind = "packing"\ncount = 100000000\n'
            'region = { min = [0, 0, 0], max = [100, 100, 100] }').replace(
                "radius = 0.01\n", "radius = 0.001\n"))

        def limit():  # 4 GB of address space: 10⁸ bodies need hundreds of GB
            resource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))

        result = subprocess.run([test_cli.GRBD, "validate", scene], capture_output=True,
                                text=True, timeout=120, preexec_fn=limit)
        self.assertEqual(result.returncode, 3, result.stderr)
        self.assertIn("big.toml: bodies[0]", result.stderr)
        self.assertIn("GB", result.stderr)

    def test_messages_name_the_file_the_group_and_the_key(self):
        for body, message in (
                ("radius = 1e-300", "radius, density: a body of radius 1e-300 m"),
                ("mass = 1e308", "radius, mass: a body of radius 0.01 m and mass 1e+308 kg")):
            text = scene_text("positions = [[0.0, 0.0, 0.0]]")
            text = text.replace("radius = 0.01\n", "radius = 1e-300\n") if "radius" in body \
                else text.replace("density = 2500.0\n", body + "\n")
            scene = self.write("m.toml", text)
            result = run("validate", scene)
            self.assertEqual(result.returncode, 3, result.stderr)
            self.assertIn("m.toml: bodies[0] (bodies[0]): " + message, result.stderr)
            self.assertIn("under- or overflows", result.stderr)
        scene = self.write("m.toml", scene_text("positions = [[0.0, 0.0, 0.0]]") +
                           "".join(f'[[material]]\nname = "m{k}"\n' for k in range(1024)))
        result = run("validate", scene)
        self.assertEqual(result.returncode, 3, result.stderr)
        self.assertRegex(result.stderr, r"m\.toml:\d+:\d+: material\[1024\]\.name: expected at "
                                        r"most 1024 materials")

    def test_a_mesh_that_is_not_obj_is_not_quoted(self):
        self.write("secret.txt", "root:x:0:0:secret-words:/root:/bin/bash\n")
        scene = self.write("mesh.toml", scene_text("positions = [[0.0, 0.0, 0.5]]",
                                                   '[[static]]\nshape = "mesh"\n'
                                                   'file = "secret.txt"\nmaterial = "glass"\n'))
        result = run("validate", scene)
        self.assertEqual(result.returncode, 3, result.stderr)
        self.assertIn("secret.txt:1: expected a statement", result.stderr)
        self.assertNotIn("secret-words", result.stderr)


class CheckpointsAreChecked(Faults):
    """Class 9: a checkpoint is checked, and named, before the first step."""

    def make(self):
        out, ckpt = self.path("good.h5"), self.path("good.ckpt.h5")
        result = run("run", SCENE, "-q", "-o", out, "-c", ckpt, "--end-time", "0.05")
        self.assertEqual(result.returncode, 0, result.stderr)
        return ckpt

    def restart(self, ckpt, out):
        return run("run", SCENE, "-q", "-o", out, "-c", self.path("r.ckpt.h5"), "-r", ckpt,
                   "--end-time", "0.06")

    def test_edited_checkpoints_are_refused_naming_the_checkpoint(self):
        good = self.make()

        def body(field, value):
            def edit(f):
                b = f["bodies"][()]
                b[field][0] = value
                f["bodies"][...] = b
            return edit

        edits = {
            "nan_position": lambda f: f["states"].__setitem__((0, 0), np.nan),
            "tiny_inertia": body("K_Theta", [3.5e-47, 1.18e-8, 1.18e-8]),
            "next_id_max": lambda f: f.attrs.__setitem__("next_id", np.uint64(2**64 - 1)),
            "steps_zero": lambda f: f.attrs.__setitem__("steps", np.uint64(0)),
            "removed_mass_nan": lambda f: f.attrs.__setitem__("removed_mass", np.nan),
            "lambda_minus_1e300": lambda f: f["warm_start_lambda"].__setitem__((0, 0), -1e300),
            "t_1e300": lambda f: f.attrs.__setitem__("t", 1e300),
        }
        for name, edit in edits.items():
            ckpt = self.path(name + ".h5")
            shutil.copy(good, ckpt)
            with h5py.File(ckpt, "r+") as f:
                edit(f)
            result = self.restart(ckpt, self.path("r.h5"))
            self.assertEqual(result.returncode, 3, (name, result.stderr))
            self.assertIn(name + ".h5: ", result.stderr)
            self.assertNotIn("s.toml:", result.stderr)
            self.assertFalse(os.path.exists(self.path("r.h5")), name)

    def test_damaged_bytes_are_refused_or_change_nothing(self):
        good = self.make()
        self.assertEqual(self.restart(good, self.path("ref.h5")).returncode, 0)
        reference = test_cli.datasets(self.path("ref.h5"))
        data = bytearray(text_of(good))
        rng = random.Random(20261127)
        refused = identical = 0
        for trial in range(40):
            damaged = bytearray(data)
            offset = rng.randrange(len(damaged))
            damaged[offset] ^= 1 << rng.randrange(8)
            ckpt, out = self.path("d.h5"), self.path(f"d{trial}.h5")
            with open(ckpt, "wb") as f:
                f.write(damaged)
            result = self.restart(ckpt, out)
            self.assertIn(result.returncode, (0, 3), (offset, result.stderr))
            if result.returncode == 3:
                self.assertIn("d.h5: ", result.stderr, offset)
                refused += 1
            else:  # a byte nothing reads: the run is the undamaged one's
                got = test_cli.datasets(out)
                self.assertEqual(sorted(got), sorted(reference))
                for key in reference:
                    self.assertTrue(np.array_equal(got[key], reference[key]), (offset, key))
                identical += 1
            if os.path.exists(out):
                os.remove(out)
        self.assertEqual(refused + identical, 40)
        print(f"\n40 bit flips: {refused} refused naming the checkpoint, {identical} restarted "
              "bit-identically", file=sys.stderr)


class FullDisks(Faults):
    """Class 10: a write that fails (a file size limit, as a full disk) ends cleanly."""

    def test_a_write_that_fails_exits_1_and_the_last_checkpoint_restarts(self):
        scene = self.chute_with("s.toml", "every = 25\n", "every = 1\n")

        def limit():  # writes beyond 4 MB fail with EFBIG, as on a full disk
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (4 << 20, 4 << 20))

        out, ckpt = self.path("o.h5"), self.path("c.h5")
        result = subprocess.run([test_cli.GRBD, "run", scene, "-q", "-o", out, "-c", ckpt],
                                capture_output=True, text=True, timeout=300, preexec_fn=limit)
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertIn("o.h5", result.stderr)
        self.assertNotIn("infinite loop", result.stderr)
        self.assertTrue(os.path.exists(ckpt))
        again = run("run", scene, "-q", "-o", self.path("o2.h5"), "-c", ckpt, "-r", ckpt,
                    "--end-time", "0.3")
        self.assertEqual(again.returncode, 0, again.stderr)


if __name__ == "__main__":
    test_cli.GRBD = os.path.abspath(sys.argv[1])
    SCENE = test_cli.SCENE = os.path.abspath(sys.argv[2])
    unittest.main(argv=[sys.argv[0], "-v"] + sys.argv[3:])
