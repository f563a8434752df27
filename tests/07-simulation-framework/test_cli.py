#!/usr/bin/env python3
"""Chapter 7: the `grbd` command line, tested as a user runs it.

Run by CTest as `test_cli.py <grbd executable> <test scene>` with Debian's python3 and h5py.
Each test works in its own temporary folder. The reference for every restart test is the output
of an uninterrupted run of the same scene: the records, the per-step table (all but the wall
times), the body table and the materials must be bit-identical.
"""

import math
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
import xml.etree.ElementTree as ET

import h5py
import numpy as np
from numpy.lib.recfunctions import repack_fields

GRBD = None
SCENE = None


def run(*args, **kwargs):
    """Runs grbd with a time limit; returns the CompletedProcess."""
    return subprocess.run([GRBD, *args], capture_output=True, text=True, timeout=600, **kwargs)


def datasets(path):
    """Every dataset of an HDF5 file as {path: numpy array}, wall-time columns left out."""
    out = {}
    with h5py.File(path, "r") as f:
        count = int(f["records"].attrs["count"])

        def visit(name, obj):
            if not isinstance(obj, h5py.Dataset):
                return
            value = obj[()]
            if value.dtype.names:
                names = [n for n in value.dtype.names if not n.startswith("seconds")]
                value = repack_fields(value[names])
            if value.dtype.kind == "O":
                value = np.array([v.decode() if isinstance(v, bytes) else v for v in value])
            # Record groups beyond `count` are not part of the file (a killed run may leave one).
            m = re.match(r"records/(\d+)/", name)
            if m and int(m.group(1)) >= count:
                return
            if name in ("records/time", "records/step", "records/bodies"):
                value = value[:count]
            out[name] = value

        f.visititems(visit)
    return out


class Scratch(unittest.TestCase):
    """A test in its own temporary folder."""

    def setUp(self):
        self._folder = tempfile.TemporaryDirectory(prefix="grbd_cli_")
        self.dir = self._folder.name

    def tearDown(self):
        self._folder.cleanup()

    def path(self, name):
        return os.path.join(self.dir, name)

    def assertSameOutput(self, reference, other):
        a = datasets(reference)
        b = datasets(other)
        self.assertEqual(sorted(a), sorted(b))
        for name in a:
            self.assertEqual(a[name].shape, b[name].shape, name)
            self.assertTrue(a[name].tobytes() == b[name].tobytes(), f"{name} differs")
        return len(a)

    def reference(self, end_time=None):
        """The output of an uninterrupted run."""
        args = ["run", SCENE, "-q", "-o", self.path("ref.h5"), "-c", self.path("ref.ckpt.h5")]
        if end_time is not None:
            args += ["--end-time", str(end_time)]
        result = run(*args)
        self.assertEqual(result.returncode, 0, result.stderr)
        return self.path("ref.h5")


class Help(Scratch):
    def test_every_subcommand_has_help_with_its_own_exit_codes(self):
        for sub in ([], ["run"], ["validate"], ["info"], ["fclib"], ["bench"]):
            result = run(*sub, "--help")
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertIn("Exit codes", result.stdout)
            # Only a run can be stopped by a signal.
            if sub in ([], ["run"]):
                self.assertIn("130", result.stdout)
            else:
                self.assertNotIn("130", result.stdout, sub)
            if sub in (["run"], ["validate"]):
                self.assertIn('chapter 7 of the book, section "Scene files"', result.stdout)

    def test_version_unknown_subcommands_and_prefixed_errors(self):
        result = run("--version")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertRegex(result.stdout.strip(), r"^grbd \d+\.\d+\.\d+$")
        result = run("frobnicate")
        self.assertEqual(result.returncode, 2)
        self.assertIn('grbd: unknown subcommand "frobnicate"', result.stderr)
        result = run("run", "nothing.toml")
        self.assertEqual(result.returncode, 2)
        self.assertTrue(result.stderr.startswith("grbd run: "), result.stderr)
        self.assertIn("nothing.toml", result.stderr)


class BadCommandLines(Scratch):
    def test_bad_options_exit_2_and_create_no_file(self):
        out = self.path("out.h5")
        with open(out, "w") as f:
            f.write("an earlier file that must survive")
        cases = [
            ["run", SCENE, "-o", out, "--bogus"],
            ["run", self.path("missing.toml"), "-o", out],
            ["run", SCENE, "-o", out, "--end-time", "-1"],
            ["run", SCENE, "-o", out, "--end-time", "soon"],
            ["run", SCENE, "-o", out, "--progress", "sometimes"],
            ["run", SCENE, "-o", out, "-c", out],
            ["frobnicate"],
            [],
        ]
        for args in cases:
            result = run(*args)
            self.assertEqual(result.returncode, 2, f"{args}: {result.stderr}")
            self.assertTrue(result.stderr.strip(), f"{args}: no message")
            with open(out) as f:
                self.assertEqual(f.read(), "an earlier file that must survive", args)
        self.assertEqual(sorted(os.listdir(self.dir)), ["out.h5"])

    def test_a_bad_scene_exits_3_naming_file_line_and_key(self):
        with open(SCENE) as f:
            text = f.read()
        bad = self.path("typo.toml")
        with open(bad, "w") as f:
            f.write(text.replace("jitter = 0.5", "jiter = 0.5"))
        line = next(i for i, l in enumerate(text.splitlines(), 1) if l.startswith("jitter"))
        result = run("run", bad, "-o", self.path("out.h5"))
        self.assertEqual(result.returncode, 3)
        self.assertIn(f"typo.toml:{line}:1: bodies[0].generator.jiter: unknown key", result.stderr)
        self.assertIn('did you mean "jitter"', result.stderr)
        self.assertFalse(os.path.exists(self.path("out.h5")))
        result = run("validate", bad)
        self.assertEqual(result.returncode, 3)

    def test_info_refuses_a_file_that_is_not_an_output(self):
        other = self.path("other.h5")
        with h5py.File(other, "w") as f:
            f["x"] = [1.0]
        result = run("info", other)
        self.assertEqual(result.returncode, 3)
        self.assertIn("other.h5: is not a grbd output file", result.stderr)
        text = self.path("text.h5")
        with open(text, "w") as f:
            f.write("not HDF5")
        result = run("info", text)
        self.assertEqual(result.returncode, 3)
        self.assertIn("is not an HDF5 file", result.stderr)


class Validate(Scratch):
    def test_validate_summarises_without_running(self):
        result = run("validate", SCENE)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("generated 100 bodies", result.stdout)
        self.assertIn("created by the inflow", result.stdout)
        self.assertTrue(result.stdout.rstrip().endswith("ok"))
        self.assertEqual(os.listdir(self.dir), [])


class Output(Scratch):
    def test_a_run_writes_records_steps_bodies_and_attributes(self):
        out = self.reference()
        with h5py.File(out, "r") as f:
            for key in ("format", "format_version", "grbd_version", "host", "date", "scene",
                        "scene_file", "precision"):
                self.assertIn(key, f.attrs)
            with open(SCENE) as s:
                self.assertEqual(f.attrs["scene"], s.read())
            count = int(f["records"].attrs["count"])
            self.assertEqual(count, 600 // 25 + 1)  # step 0, every 25 steps, the end
            self.assertEqual(len(f["steps"]), 600)
            self.assertEqual(list(f["steps"]["step"]), list(range(1, 601)))
            self.assertEqual(len(f["bodies"]), len(set(f["bodies"]["id"])))
            for k in range(count):
                group = f["records/%06d" % k]
                ids = group["id"][()]
                self.assertTrue(np.all(np.diff(ids.astype(np.int64)) > 0), "ids ascending")
                self.assertEqual(group["I_r_S"].shape, (len(ids), 3))
                self.assertEqual(group["p"].shape, (len(ids), 4))
                norms = np.linalg.norm(group["p"][()], axis=1)
                self.assertLess(np.max(np.abs(norms - 1.0)), 1e-12)
                self.assertEqual(group["I_r_S"].dtype, np.float64)
                self.assertEqual(f["records/time"][k], group.attrs["time"])
                # Every dataset says its unit, and its frame where it has one.
                for name, unit, frame in (("id", "1", None), ("I_r_S", "m", "I"),
                                          ("p", "1", "K to I"), ("I_v_S", "m/s", "I"),
                                          ("K_omega", "rad/s", "K"), ("radius", "m", None)):
                    self.assertEqual(group[name].attrs["unit"], unit, name)
                    self.assertEqual(group[name].attrs.get("frame"), frame, name)
            self.assertEqual(f["records/time"].attrs["unit"], "s")
            self.assertIn("t: s", f["steps"].attrs["units"])
            self.assertIn("mass: kg", f["bodies"].attrs["units"])
            last = f["records/%06d" % (count - 1)]
            # Bodies left through the outlet and the inflow added some: both show in the ids.
            self.assertLess(len(last["id"]), len(f["bodies"]))
            self.assertGreater(len(f["bodies"]), 100)
        result = run("info", out)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn(f"records: {count}", result.stdout)
        # Steps that did not converge are explained by the cap they stopped at.
        with h5py.File(out, "r") as f:
            steps = f["steps"][()]
        stopped = steps[steps["converged"] == 0]
        self.assertGreater(len(stopped), 0)  # the chute's solver is capped at 300 iterations
        self.assertIn(f"{len(stopped)} steps stopped at the cap of "
                      f"{int(stopped['iterations'].max())} iterations", result.stdout)
        self.assertEqual(int(stopped["iterations"].max()), 300)
        # The accuracy of the run (chapter 6), recomputed here from the file's own tables: the
        # share of steps converged and the sweeps from /steps, the overlaps' mean weighted by the
        # contacts of each step, their largest, and the 99th percentile of the records' histograms
        # (the upper edge of the bin holding it, 20 bins a decade above 1e-8 r).
        with h5py.File(out, "r") as f:
            table = f["records/overlaps"]
            counts = table[()].sum(axis=0)
            unit = float(table.attrs["unit"])
        n = len(steps)
        converged = int(steps["converged"].sum())
        self.assertIn(f"solver: {converged} of {n} steps converged "
                      f"({100.0 * converged / n:.3g} %), sweeps a step: mean "
                      f"{steps['iterations'].mean():.3g}, largest {int(steps['iterations'].max())}",
                      result.stdout)
        mean = float((steps["mean_penetration"] * steps["contacts"]).sum() / steps["contacts"].sum())
        largest = float(steps["max_penetration"].max())
        need = max(1, math.ceil(0.99 * counts.sum()))
        b = int(np.argmax(np.cumsum(counts) >= need))
        p99 = 10.0 ** (-8 + b / 20) * unit
        self.assertIn(f"overlaps: mean {mean:.3g} m ({mean / unit:.3g} r), 99th percentile "
                      f"{p99:.3g} m ({p99 / unit:.3g} r) (at the records), largest {largest:.3g} m",
                      result.stdout)
        self.assertGreater(largest, 0.0)

    def test_float32_records_on_request(self):
        with open(SCENE) as f:
            text = f.read()
        scene = self.path("float.toml")
        with open(scene, "w") as f:
            f.write(text.replace("every = 25\n", 'every = 25\nprecision = "float"\n'))
        result = run("run", scene, "-q", "-o", self.path("f.h5"), "-c", self.path("f.ckpt.h5"),
                     "--end-time", "0.05")
        self.assertEqual(result.returncode, 0, result.stderr)
        with h5py.File(self.path("f.h5"), "r") as f:
            self.assertEqual(f["records/000001/I_r_S"].dtype, np.float32)
            self.assertEqual(f.attrs["precision"], "float")

    def test_the_xdmf_names_only_datasets_that_exist_with_its_shapes(self):
        out = self.reference()
        xmf = out[:-3] + ".xmf"
        tree = ET.parse(xmf)
        grids = tree.findall(".//Grid[@GridType='Collection']/Grid[@GridType='Uniform']")
        with h5py.File(out, "r") as f:
            # The static geometry: one grid of triangles outside the records, on /static.
            static = tree.findall("./Domain/Grid[@Name='static']")
            self.assertEqual(len(static), 1)
            triangles = f["static/triangles"][()]
            points = f["static/points"][()]
            self.assertEqual(int(static[0].find("Topology").get("NumberOfElements")),
                             len(triangles))
            self.assertEqual([i.text.split(":", 1)[1] for i in static[0].iter("DataItem")],
                             ["/static/triangles", "/static/points", "/static/object"])
            self.assertEqual(triangles.max(), len(points) - 1)
            self.assertEqual(list(f["static/names"].asstr()), ["slope", "left wall", "right wall"])
            self.assertEqual(list(f["static/shape"]), [3, 3, 3])  # half-spaces
            self.assertEqual(f["static/points"].attrs["unit"], "m")
            self.assertEqual(sorted(set(f["static/object"])), [0, 1, 2])
            count = int(f["records"].attrs["count"])
            # Records without bodies have no grid (ParaView cannot show an empty one).
            with_bodies = [k for k in range(count) if f["records/bodies"][k] > 0]
            self.assertEqual(len(grids), len(with_bodies))
            items = 0
            for grid in grids:
                n = int(grid.find("Topology").get("NumberOfElements"))
                for item in grid.iter("DataItem"):
                    self.assertEqual(item.get("Format"), "HDF")
                    file_name, dataset = item.text.strip().split(":", 1)
                    self.assertEqual(file_name, os.path.basename(out))
                    self.assertIn(dataset, f, dataset)
                    dims = tuple(int(d) for d in item.get("Dimensions").split())
                    self.assertEqual(f[dataset].shape, dims, dataset)
                    self.assertEqual(dims[0], n)
                    self.assertEqual(int(item.get("Precision")), f[dataset].dtype.itemsize)
                    items += 1
            self.assertEqual(items, 5 * len(grids))
            times = [float(g.find("Time").get("Value")) for g in grids]
            self.assertEqual(times, [f["records/time"][k] for k in with_bodies])


COLUMN = """[simulation]
dt = 1e-3
end_time = 0.01
[solver]
tolerance = 1e-12
max_iterations = 2000
[[material]]
name = "glass"
[default_contact]
mu = 0.5
[[static]]
name = "floor"
shape = "half_space"
normal = [0.0, 0.0, 1.0]
material = "glass"
[[bodies]]
name = "column"
radius = 0.01
density = 2500.0
material = "glass"
positions = [[0.0, 0.0, 0.01], [0.0, 0.0, 0.03], [0.0, 0.0, 0.05], [0.0, 0.0, 0.07], [0.0, 0.0, 0.09]]
[output]
every = 5
contacts = true
"""


class Contacts(Scratch):
    """[output] contacts: each record holds the contacts of its step, checked against a column of
    spheres at rest on a floor, whose k-th contact from the top carries λ_N = k m g Δt."""

    def column(self, text=COLUMN):
        scene = self.path("column.toml")
        with open(scene, "w") as f:
            f.write(text)
        out = self.path("column.h5")
        result = run("run", scene, "-q", "-o", out, "-c", self.path("column.ckpt.h5"))
        self.assertEqual(result.returncode, 0, result.stderr)
        return out

    def test_a_column_of_spheres_carries_k_m_g_dt_at_its_kth_contact(self):
        out = self.column()
        m = 4.0 / 3.0 * np.pi * 0.01 ** 3 * 2500.0
        static = 1 << 63  # the tag of a static object's id
        with h5py.File(out, "r") as f:
            self.assertEqual(list(f["records/contacts"]), [0, 5, 5])  # none before a step
            self.assertEqual(f["records/000000/contacts/lambda_N"].shape, (0,))
            for k in (1, 2):
                c = f["records/%06d/contacts" % k]
                ids = [tuple(int(i) for i in row) for row in c["ids"][()]]
                # Sorted by key: (0, 1), (0, floor), (1, 2), (2, 3), (3, 4).
                self.assertEqual(ids, [(0, 1), (0, static), (1, 2), (2, 3), (3, 4)])
                below = {(0, 1): 4, (0, static): 5, (1, 2): 3, (2, 3): 2, (3, 4): 1}
                expected = [below[i] * m * 9.81 * 1e-3 for i in ids]
                # To the solver's tolerance (the column settles by 10⁻¹⁰ m/s in these steps).
                np.testing.assert_allclose(c["lambda_N"][()], expected, rtol=1e-7)
                self.assertLess(np.abs(c["lambda_T"][()]).max(), 1e-15)
                # The normal points from side b to side a: down from the upper sphere, up from
                # the floor.
                np.testing.assert_allclose(c["normal"][()][:, 2], [-1, 1, -1, -1, -1], atol=1e-15)
                np.testing.assert_allclose(c["point"][()][:, 2], [0.02, 0.0, 0.04, 0.06, 0.08],
                                           atol=1e-6)
                # A line per contact from side a to side b: the centres of the bodies, and the
                # contact point on the floor.
                line = c["line"][()]
                np.testing.assert_allclose(line[:, 2], [0.01, 0.03, 0.01, 0.0, 0.03, 0.05,
                                                        0.05, 0.07, 0.07, 0.09], atol=1e-6)
                self.assertEqual(c["lambda_N"].attrs["unit"], "N s")
                self.assertEqual(c["lambda_T"].attrs["frame"], "I")
        # The XDMF: each record a spatial collection of bodies and contacts; every data item
        # names a dataset of that shape.
        tree = ET.parse(out[:-3] + ".xmf")
        grids = tree.findall(".//Grid[@Name='contacts']")
        self.assertEqual(len(grids), 2)
        with h5py.File(out, "r") as f:
            for grid in grids:
                self.assertEqual(grid.find("Topology").get("TopologyType"), "Polyline")
                for item in grid.iter("DataItem"):
                    dataset = item.text.strip().split(":", 1)[1]
                    dims = tuple(int(d) for d in item.get("Dimensions").split())
                    self.assertEqual(f[dataset].shape, dims, dataset)

    def test_a_restart_keeps_the_contacts_and_refuses_a_scene_that_changes_them(self):
        reference = self.column()
        os.rename(reference, self.path("ref.h5"))
        os.rename(reference[:-3] + ".xmf", self.path("ref.xmf"))
        scene = self.path("column.toml")
        out, ckpt = self.path("column.h5"), self.path("column.ckpt.h5")
        first = run("run", scene, "-q", "-o", out, "-c", ckpt, "--end-time", "0.007", "--force")
        self.assertEqual(first.returncode, 0, first.stderr)
        second = run("run", scene, "-q", "-o", out, "-c", ckpt, "--restart", ckpt)
        self.assertEqual(second.returncode, 0, second.stderr)
        self.assertSameOutput(self.path("ref.h5"), out)
        with open(scene, "w") as f:
            f.write(COLUMN.replace("contacts = true", "contacts = false"))
        third = run("run", scene, "-q", "-o", out, "-c", ckpt, "--restart", ckpt)
        self.assertNotEqual(third.returncode, 0)
        self.assertIn("contacts", third.stderr)


class Restart(Scratch):
    def test_n_steps_restart_n_steps_is_bit_identical_to_2n(self):
        reference = self.reference()
        out, ckpt = self.path("b.h5"), self.path("b.ckpt.h5")
        # 310 steps: neither a record nor a checkpoint step; the restart must drop the extra
        # last record of the first run.
        first = run("run", SCENE, "-q", "-o", out, "-c", ckpt, "--end-time", "0.155")
        self.assertEqual(first.returncode, 0, first.stderr)
        second = run("run", SCENE, "-q", "-o", out, "-c", ckpt, "--restart", ckpt)
        self.assertEqual(second.returncode, 0, second.stderr)
        self.assertNotIn("warning", second.stderr)  # the same scene
        n = self.assertSameOutput(reference, out)
        with h5py.File(out, "r") as f:
            self.assertEqual(int(f.attrs["restarts"]), 1)
            self.assertRegex(f.attrs["restart_date"], r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ$")
            self.assertEqual(f.attrs["restart_host"], f.attrs["host"])
        self.assertGreater(n, 50)
        # The XDMF: appended record by record in one run, written whole at the restart and
        # appended to after it; the same text either way (but for the HDF5 file's name).
        def xdmf(h5):
            with open(h5[:-3] + ".xmf") as f:
                return f.read().replace(os.path.basename(h5) + ":", "OUTPUT:")
        self.assertEqual(xdmf(out), xdmf(reference))
        self.assertGreater(xdmf(out).count("<Grid Name=\"record"), 10)


    def test_a_restart_with_a_changed_scene_warns_naming_the_line(self):
        out, ckpt = self.path("w.h5"), self.path("w.ckpt.h5")
        first = run("run", SCENE, "-q", "-o", out, "-c", ckpt, "--end-time", "0.05")
        self.assertEqual(first.returncode, 0, first.stderr)
        with open(SCENE) as f:
            lines = f.read().split("\n")
        k = next(i for i, line in enumerate(lines) if line.startswith("mu = "))
        changed = lines[:k] + ["mu = 0.25"] + lines[k + 1:]
        scene = self.path("changed.toml")
        with open(scene, "w") as f:
            f.write("\n".join(changed))
        second = run("run", scene, "-q", "-o", out, "-c", ckpt, "--restart", ckpt,
                     "--end-time", "0.06")
        self.assertEqual(second.returncode, 0, second.stderr)
        self.assertIn("grbd run: warning: %s:%d: the scene differs" % (scene, k + 1), second.stderr)
        self.assertIn('it has "mu = 0.25", the checkpoint\'s has "%s"' % lines[k], second.stderr)
        with h5py.File(out, "r") as f:
            self.assertEqual(int(f.attrs["restarts"]), 1)

    def test_restarting_a_finished_run_changes_nothing(self):
        out, ckpt = self.path("f.h5"), self.path("f.ckpt.h5")
        first = run("run", SCENE, "-q", "-o", out, "-c", ckpt, "--end-time", "0.155")
        self.assertEqual(first.returncode, 0, first.stderr)
        shutil.copy(out, self.path("before.h5"))
        again = run("run", SCENE, "-q", "-o", out, "-c", ckpt, "--restart", ckpt, "--end-time", "0.155")
        self.assertEqual(again.returncode, 0, again.stderr)
        self.assertSameOutput(self.path("before.h5"), out)

    def test_a_restart_into_a_new_output_lists_every_body_it_records(self):
        out, ckpt = self.path("m.h5"), self.path("m.ckpt.h5")
        first = run("run", SCENE, "-q", "-o", out, "-c", ckpt, "--end-time", "0.155")
        self.assertEqual(first.returncode, 0, first.stderr)
        os.remove(out)
        second = run("run", SCENE, "-q", "-o", out, "-c", ckpt, "--restart", ckpt)
        self.assertEqual(second.returncode, 0, second.stderr)
        with h5py.File(out, "r") as f:
            known = set(f["bodies"]["id"])
            count = int(f["records"].attrs["count"])
            self.assertGreater(count, 1)
            for k in range(count):
                self.assertTrue(set(f["records/%06d/id" % k][()]) <= known, k)


class Signals(Scratch):
    END = "2.0"  # 4000 steps: a few seconds

    def start(self, out, ckpt):
        return subprocess.Popen([GRBD, "run", SCENE, "--progress", "lines", "-o", out, "-c", ckpt,
                                 "--end-time", self.END],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def wait_for(self, path, process):
        deadline = time.time() + 120
        while not os.path.exists(path):
            self.assertIsNone(process.poll(), "the run ended before " + path)
            self.assertLess(time.time(), deadline)
            time.sleep(0.01)

    def test_sigint_and_sigterm_checkpoint_close_and_resume_bit_identically(self):
        reference = self.reference(self.END)
        for sig, code in ((signal.SIGINT, 130), (signal.SIGTERM, 143)):
            out, ckpt = self.path(f"s{code}.h5"), self.path(f"s{code}.ckpt.h5")
            process = self.start(out, ckpt)
            self.wait_for(ckpt, process)
            time.sleep(0.3)
            process.send_signal(sig)
            stdout, stderr = process.communicate(timeout=120)
            self.assertEqual(process.returncode, code, stderr)
            self.assertIn("stopped", stdout)
            with h5py.File(out, "r") as f:  # closed cleanly: it opens
                stopped_at = int(f["steps"]["step"][-1])
            self.assertLess(stopped_at, 4000)
            result = run("run", SCENE, "-q", "-o", out, "-c", ckpt, "--restart", ckpt,
                         "--end-time", self.END)
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertSameOutput(reference, out)

    def test_kill_9_leaves_a_valid_checkpoint_and_a_readable_output(self):
        reference = self.reference(self.END)
        rng = random.Random(20261125)
        for trial in range(3):
            out, ckpt = self.path(f"k{trial}.h5"), self.path(f"k{trial}.ckpt.h5")
            process = self.start(out, ckpt)
            self.wait_for(ckpt, process)
            time.sleep(rng.uniform(0.0, 1.0))
            process.kill()
            process.communicate(timeout=120)
            self.assertEqual(process.returncode, -signal.SIGKILL)
            # The output opens and every record it counts equals the uninterrupted run's.
            with h5py.File(out, "r") as f, h5py.File(reference, "r") as g:
                count = int(f["records"].attrs["count"])
                self.assertGreaterEqual(count, 1)
                for k in range(count):
                    for name in ("id", "I_r_S", "p", "I_v_S", "K_omega"):
                        a = f["records/%06d/%s" % (k, name)][()]
                        b = g["records/%06d/%s" % (k, name)][()]
                        self.assertTrue(np.array_equal(a, b), f"record {k} {name}")
            # The checkpoint is valid: the run resumes from it and rewrites what follows it.
            result = run("run", SCENE, "-q", "-o", out, "-c", ckpt, "--restart", ckpt,
                         "--end-time", self.END)
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertSameOutput(reference, out)
            self.assertFalse(os.path.exists(ckpt + ".tmp") and os.path.getsize(ckpt + ".tmp") == 0)


# The FCLIB problems shipped with chapter 5.
FCLIB_DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "chapters",
                          "05-contact-laws", "data")


class Fclib(Scratch):
    def test_fclib_solves_a_problem_with_every_solver_to_the_tolerance(self):
        problem = os.path.join(FCLIB_DATA, "Spheres-i099-356-679.hdf5")
        csv = self.path("history.csv")
        result = run("fclib", problem, "--tol", "1e-6", "--csv", csv)
        self.assertEqual(result.returncode, 0, result.stderr)
        rows = [line.split() for line in result.stdout.splitlines()[1:]]
        solvers = [" ".join(r[1:-5]) for r in rows]
        self.assertEqual(solvers, ["SOR-AC", "SOR-DS", "JOR", "APGD", "Newton", "Newton-GMRES",
                                   "SOR-AC warm"])
        for r in rows:
            self.assertEqual(r[0], "Spheres-i099-356-679")
            self.assertEqual(int(r[-5]), 356)          # contacts
            self.assertLessEqual(float(r[-3]), 1e-6)   # |F|/|q|
        self.assertNotIn("NOT converged", result.stdout)
        with open(csv) as f:
            lines = f.read().splitlines()
        self.assertEqual(lines[0], "problem,solver,k,relative_residual")
        total = sum(int(r[-4]) for r in rows)          # one line per iteration of every solve
        self.assertEqual(len(lines) - 1, total)
        last = float(lines[-1].split(",")[3])
        self.assertLessEqual(last, 1e-6)

    def test_fclib_says_the_caps_it_ran_with(self):
        problem = os.path.join(FCLIB_DATA, "Spheres-i099-356-679.hdf5")
        for args, caps in (([], "caps: 20000 iterations, Newton 200"),
                           (["--max-iterations", "7"], "caps: 7 iterations, Newton 7")):
            result = run("fclib", problem, *args)
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertTrue(result.stdout.splitlines()[0].endswith(caps), result.stdout)
            rows = [line.split() for line in result.stdout.splitlines()[1:]]
            cap = int(caps.split()[-1])
            for r in rows:
                if r[1].startswith("Newton"):  # problem, solver, contacts, iterations, …
                    self.assertLessEqual(int(r[3]), cap, r)
        self.assertIn("Newton's methods at most 200", run("fclib", "--help").stdout)

    def test_fclib_refuses_bad_problems_and_options(self):
        text = self.path("not.hdf5")
        with open(text, "w") as f:
            f.write("not an HDF5 file\n")
        for args, code, message in (
                (["/nonexistent"], 3, "/nonexistent"),
                ([text], 3, "not.hdf5"),
                ([self.dir], 3, "not.hdf5"),  # a folder: its *.hdf5 files are read
                (["--tol", "-1", FCLIB_DATA], 2, "--tol"),
                (["--tol", "nan", FCLIB_DATA], 2, "--tol"),
                (["--max-iterations", "0", FCLIB_DATA], 2, "--max-iterations")):
            result = run("fclib", *args)
            self.assertEqual(result.returncode, code, (args, result.stderr))
            self.assertIn(message, result.stderr)
            self.assertEqual(result.stdout, "")


class Bench(Scratch):
    def test_bench_lists_runs_and_passes_options_on(self):
        result = run("bench", "--list")
        self.assertEqual(result.returncode, 0, result.stderr)
        names = result.stdout.split()
        for name in ("ch02_bench_integrators", "ch04_bench_broad_phase", "ch05_bench_sor",
                     "ch06_bench_step"):
            self.assertIn(name, names)
        # --benchmark_list_tests goes to the program, which lists its benchmarks and exits 0.
        result = run("bench", "ch02", "--benchmark_list_tests=true")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertIn("== ch02_bench_integrators", result.stdout)
        self.assertGreater(len(result.stdout.splitlines()), 2)
        result = run("bench", "no_such_benchmark")
        self.assertEqual(result.returncode, 2)
        self.assertIn("no_such_benchmark", result.stderr)


if __name__ == "__main__":
    GRBD = os.path.abspath(sys.argv[1])
    SCENE = os.path.abspath(sys.argv[2])
    unittest.main(argv=[sys.argv[0], "-v"] + sys.argv[3:])
