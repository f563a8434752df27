#!/usr/bin/env python3
"""Chapter 8: `mpiexec -n P grbd run`, tested as a user runs it.

Run by CTest as `test_grbd_mpi.py <grbd> <mpiexec> <ballistic scene> <pile scene>` with Debian's
python3 and h5py. The reference is always the serial run of the same scene: for bodies that never
touch (the ballistic scene) every record, the body table, the step table and the checkpoint's
bodies and states must be bit-identical for any number of processes, the energies and the mass
the outlet removed excepted, which are sums over processes taken in another order (equal to 10⁻¹³
relative).
"""

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import h5py
import numpy as np
from numpy.lib.recfunctions import repack_fields

GRBD = MPIEXEC = BALLISTIC = PILE = None
ENERGIES = ("kinetic_energy", "potential_energy")
os.environ.update({"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
                   "OMPI_MCA_btl": "self,vader,tcp", "OMPI_MCA_mpi_yield_when_idle": "1",
                   "OMPI_MCA_rmaps_base_oversubscribe": "1"})


def grbd(processes, *args, timeout=300):
    """grbd serially (processes = 0: no mpiexec) or under mpiexec with that many processes."""
    launcher = [] if processes == 0 else [MPIEXEC, "-n", str(processes), "--oversubscribe",
                                          "--bind-to", "none"]
    return subprocess.run([*launcher, GRBD, *args], capture_output=True, text=True,
                          timeout=timeout)


def tables(path):
    """The output's datasets as {name: array} (wall times and energies of /steps left out) and
    the energies apart."""
    out, energies = {}, {}
    with h5py.File(path, "r") as f:
        def visit(name, obj):
            if not isinstance(obj, h5py.Dataset) or name.startswith("static"):
                return
            value = obj[()]
            if name == "steps":
                for e in ENERGIES:
                    energies[e] = value[e]
                keep = [n for n in value.dtype.names
                        if not n.startswith("seconds") and n not in ENERGIES]
                value = repack_fields(value[keep])
            out[name] = value
        f.visititems(visit)
        attrs = {k: f.attrs[k] for k in ("format", "format_version", "scene", "dt", "precision")}
    return out, energies, attrs


def checkpoint(path):
    """A checkpoint's bodies and states in ascending id, and its other datasets and attributes."""
    with h5py.File(path, "r") as f:
        order = np.argsort(f["bodies"]["id"][()], kind="stable")
        data = {"bodies": f["bodies"][()][order], "states": f["states"][()][order]}
        for name in ("generators", "warm_start_keys", "warm_start_lambda"):
            data[name] = f[name][()]
        attrs = {k: v for k, v in f.attrs.items() if k != "checksum"}
    return data, attrs


class Runs(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="grbd-mpi-")
        self.addCleanup(shutil.rmtree, self.dir, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.dir, name)

    def run_ok(self, processes, *args):
        result = grbd(processes, *args)
        self.assertEqual(result.returncode, 0, f"P = {processes}: {result.stderr}")
        return result

    def assert_same_output(self, reference, other):
        a, ea, attrs_a = tables(reference)
        b, eb, attrs_b = tables(other)
        self.assertEqual(sorted(a), sorted(b))
        for name in a:
            self.assertTrue(np.array_equal(a[name], b[name]), f"{other}: {name} differs")
        for e in ENERGIES:
            np.testing.assert_allclose(eb[e], ea[e], rtol=1e-13, atol=1e-300, err_msg=e)
        for key in attrs_a:
            self.assertEqual(attrs_a[key], attrs_b[key], key)


class BitIdentical(Runs):
    """Bodies that never touch: the parallel run is the serial run, bit for bit."""

    def serial(self):
        self.run_ok(0, "run", BALLISTIC, "-q", "-o", self.path("s.h5"), "-c", self.path("s.c.h5"))
        return self.path("s.h5")

    def test_any_number_of_processes_writes_the_serial_output(self):
        reference = self.serial()
        with h5py.File(reference, "r") as f:  # the scene does what the test needs
            self.assertGreater(len(f["bodies"]), int(f["records/bodies"][0]))  # inflow
            self.assertLess(int(f["records/bodies"][-1]), len(f["bodies"]))    # outlet
            self.assertEqual(int(f["steps"]["contacts"].max()), 0)
        ref_ckpt = checkpoint(self.path("s.c.h5"))
        for p in (2, 3, 4):
            out, ckpt = self.path(f"p{p}.h5"), self.path(f"p{p}.c.h5")
            result = self.run_ok(p, "run", BALLISTIC, "-o", out, "-c", ckpt)
            self.assertEqual(result.stdout.count("done:"), 1, result.stdout)  # rank 0 speaks
            self.assert_same_output(reference, out)
            data, attrs = checkpoint(ckpt)
            for name, value in ref_ckpt[0].items():
                self.assertTrue(np.array_equal(value, data[name]), f"P = {p}: checkpoint {name}")
            for key, value in ref_ckpt[1].items():
                if key == "removed_mass":  # a sum over processes, in another order
                    self.assertAlmostEqual(value, attrs[key], delta=1e-13 * value)
                else:
                    self.assertEqual(value, attrs[key], f"P = {p}: checkpoint attribute {key}")

    def test_a_run_restarted_on_4_then_2_then_1_processes_continues_bit_for_bit(self):
        reference = self.serial()
        out, ckpt = self.path("r.h5"), self.path("r.c.h5")
        self.run_ok(4, "run", BALLISTIC, "-q", "-o", out, "-c", ckpt, "--end-time", "0.035")
        self.run_ok(2, "run", BALLISTIC, "-q", "-o", out, "-c", ckpt, "-r", ckpt,
                    "--end-time", "0.081")
        self.run_ok(0, "run", BALLISTIC, "-q", "-o", out, "-c", ckpt, "-r", ckpt)
        self.assert_same_output(reference, out)


class Failures(Runs):
    """Errors end every process with one message and the serial run's exit code, never a hang."""

    def scene(self, extra):
        text = ('[simulation]\ndt = 1e-3\nend_time = 3e-3\n\n[[material]]\nname = "glass"\n\n'
                '[default_contact]\nmu = 0.5\n\n[[bodies]]\nname = "still"\nradius = 0.01\n'
                'density = 2500.0\nmaterial = "glass"\npositions = [[0.0, 0.0, 0.0], '
                '[0.5, 0.0, 0.0], [1.0, 0.0, 0.0]]\n' + extra)
        with open(self.path("s.toml"), "w") as f:
            f.write(text)
        return self.path("s.toml")

    def test_a_step_that_fails_on_one_process_ends_all(self):
        # Only the process that owns the body at x = 1 m sees it blow up.
        scene = self.scene('[[bodies]]\nname = "wild"\nradius = 0.01\ndensity = 2500.0\n'
                           'material = "glass"\nvelocity = [1e308, 1e308, 0.0]\n'
                           'positions = [[1.0, 0.3, 0.0]]\n[output]\nevery = 1\n')
        start = time.monotonic()
        result = grbd(3, "run", scene, "-q", "-o", self.path("o.h5"), "-c", self.path("c.h5"),
                      timeout=120)
        self.assertLess(time.monotonic() - start, 60)
        self.assertEqual(result.returncode, 1, result.stderr)
        self.assertEqual(result.stderr.count("blew up"), 1, result.stderr)
        self.assertRegex(result.stderr, r"grbd: rank \d: the run failed: .*step 1 .*body 3 blew up")
        with h5py.File(self.path("o.h5"), "r") as f:  # the record before the failure
            self.assertEqual(int(f["records"].attrs["count"]), 1)
        self.assertFalse(os.path.exists(self.path("c.h5")))

    def test_an_error_only_rank_0_finds_ends_all_with_the_serial_exit_code(self):
        scene = self.scene("")
        result = grbd(2, "run", scene, "-o", os.path.join(self.dir, "none", "o.h5"), "-c",
                      self.path("c.h5"), timeout=120)
        self.assertEqual(result.returncode, 3, result.stderr)
        self.assertEqual(result.stderr.count("grbd run:"), 1, result.stderr)
        self.assertIn("rank 0:", result.stderr)
        self.assertIn("does not exist", result.stderr)
        serial = grbd(0, "run", scene, "-o", os.path.join(self.dir, "none", "o.h5"))
        self.assertEqual(serial.returncode, 3, serial.stderr)

    def test_sigterm_to_mpiexec_leaves_a_checkpoint_that_restarts(self):
        out, ckpt = self.path("k.h5"), self.path("k.c.h5")
        process = subprocess.Popen([MPIEXEC, "-n", "2", "--oversubscribe", "--bind-to", "none",
                                    GRBD, "run", PILE, "-q", "-o", out, "-c", ckpt,
                                    "--end-time", "0.2"],
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        # Stop once the first record after step 0 is in (the pile records every 100 steps).
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            time.sleep(0.5)
            try:
                with h5py.File(out, "r", locking=False) as f:
                    if int(f["records"].attrs["count"]) >= 2:
                        break
            except (OSError, KeyError):
                pass
        process.send_signal(signal.SIGTERM)
        _, stderr = process.communicate(timeout=120)
        self.assertNotEqual(process.returncode, 0, stderr)
        with h5py.File(ckpt, "r") as f:
            steps = int(f.attrs["steps"])
        self.assertGreater(steps, 0)
        self.assertLess(steps, 1000, "the run ended before the signal: nothing was tested")
        result = self.run_ok(0, "run", PILE, "-q", "-o", out, "-c", ckpt, "-r", ckpt,
                             "--end-time", "0.2")
        with h5py.File(out, "r") as f:
            self.assertEqual(len(f["steps"]), 1000, result.stderr)
            self.assertAlmostEqual(float(f["records/time"][int(f["records"].attrs["count"]) - 1]),
                                   0.2, delta=1e-12)

    def test_the_stop_file_stops_every_process_with_a_checkpoint(self):
        for processes in (2, 0):
            out, ckpt = self.path(f"s{processes}.h5"), self.path(f"s{processes}.c.h5")
            stop = ckpt + ".stop"
            launcher = [] if processes == 0 else [MPIEXEC, "-n", str(processes),
                                                  "--oversubscribe", "--bind-to", "none"]
            process = subprocess.Popen([*launcher, GRBD, "run", PILE, "-q", "-o", out, "-c",
                                        ckpt, "--end-time", "0.2"],
                                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            deadline = time.monotonic() + 120
            while not os.path.exists(out) and time.monotonic() < deadline:
                time.sleep(0.2)
            time.sleep(1.0)
            open(stop, "w").close()
            _, stderr = process.communicate(timeout=120)
            # mpiexec reports a process's non-zero code; the serial run exits with it
            self.assertNotEqual(process.returncode, 0, stderr)
            if processes == 0:
                self.assertEqual(process.returncode, 4, stderr)
            self.assertFalse(os.path.exists(stop), "the stop file is removed once honoured")
            with h5py.File(ckpt, "r") as f:
                steps = int(f.attrs["steps"])
            with h5py.File(out, "r") as f:
                self.assertEqual(len(f["steps"]), steps)
            self.assertLess(steps, 1000, "the run ended before the stop file: nothing was tested")


if __name__ == "__main__":
    GRBD, MPIEXEC, BALLISTIC, PILE = sys.argv[1:5]
    unittest.main(argv=sys.argv[:1] + sys.argv[5:], verbosity=2)
