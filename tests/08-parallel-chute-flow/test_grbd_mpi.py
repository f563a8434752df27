#!/usr/bin/env python3
"""Chapter 8: `mpiexec -n P grbd run`, tested as a user runs it.

Run by CTest as `test_grbd_mpi.py <grbd> <mpiexec> <ballistic scene> <pile scene>` with Debian's
python3 and h5py. The reference is always the serial run of the same scene: for bodies that never
touch (the ballistic scene) every record, the body table, the step table and the checkpoint's
bodies and states must be bit-identical for any number of processes, the energies and the mass
the outlet removed excepted, which are sums over processes taken in another order (equal to 10⁻¹³
relative).
"""

import math
import os
import re
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
        # Written collectively in the global order of ids, the checkpoint's state is the same
        # whatever the number of processes: its checksum (over every row, in order) included. The
        # cuts its processes stepped on are kept beside it (dataset distribution), with their own
        # checksum.
        checksums = set()
        for p in (2, 3, 4):
            with h5py.File(self.path(f"p{p}.c.h5"), "r") as f:
                checksums.add(int(f.attrs["checksum"]))
        self.assertEqual(len(checksums), 1, checksums)

    def test_a_bisection_tree_of_3_and_5_processes_writes_the_serial_output(self):
        # Recursive coordinate bisection instead of the grid: leaves that do not line up, rebalanced
        # every 10 steps as the lattice flies out and the stream flies in.
        with open(BALLISTIC) as f:
            text = f.read()
        scene = self.path("tree.toml")
        with open(scene, "w") as f:
            f.write(text + '\n[parallel]\npartition = "bisection"\nrebalance_every = 10\n'
                    'imbalance = 1.05\n')
        self.run_ok(0, "run", scene, "-q", "-o", self.path("ts.h5"), "-c", self.path("ts.c.h5"))
        for p in (3, 5):
            out = self.path(f"t{p}.h5")
            result = self.run_ok(p, "run", scene, "-o", out, "-c", self.path(f"t{p}.c.h5"))
            self.assertRegex(result.stdout, r"[1-9]\d* rebalances")  # the tree was re-cut
            self.assert_same_output(self.path("ts.h5"), out)

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
        # The process that met it ends the run once the agreement's patience (20 s) has passed:
        # the others wait inside the step's exchanges.
        self.assertRegex(result.stderr, r"grbd: rank \d: .*step 1 .*body 3 blew up")
        with h5py.File(self.path("o.h5"), "r") as f:  # the record before the failure
            self.assertEqual(int(f["records"].attrs["count"]), 1)
        self.assertFalse(os.path.exists(self.path("c.h5")))

    def test_an_error_only_rank_0_finds_ends_all_with_the_serial_exit_code(self):
        scene = self.scene("")
        result = grbd(2, "run", scene, "-o", os.path.join(self.dir, "none", "o.h5"), "-c",
                      self.path("c.h5"), timeout=120)
        self.assertEqual(result.returncode, 3, result.stderr)
        self.assertEqual(result.stderr.count("grbd run:"), 1, result.stderr)
        self.assertIn("does not exist", result.stderr)
        serial = grbd(0, "run", scene, "-o", os.path.join(self.dir, "none", "o.h5"), "-c",
                      self.path("c.h5"))
        self.assertEqual(serial.returncode, 3, serial.stderr)
        # Rank 0 speaks for the run: the serial run's message, without a rank.
        self.assertEqual(result.stderr.splitlines()[0], serial.stderr.strip())

    def test_a_full_disk_ends_every_process_with_one_message(self):
        # The output on a file system of 300 KiB: the first record's collective write fails on
        # the process that allocates the datasets while the other waits inside parallel HDF5.
        folder = os.path.join(self.dir, "full")
        os.mkdir(folder)
        mount = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=300k", "tmpfs", folder],
                               capture_output=True) if os.geteuid() == 0 else None
        if mount is None or mount.returncode != 0:
            self.skipTest("needs root and a tmpfs mount")
        try:
            out = os.path.join(folder, "o.h5")
            start = time.monotonic()
            result = grbd(2, "run", PILE, "-q", "-o", out, "-c", os.path.join(folder, "c.h5"),
                          timeout=120)
            self.assertLess(time.monotonic() - start, 90)  # no hang: ended after the patience
            self.assertEqual(result.returncode, 1, result.stderr)
            self.assertEqual(result.stderr.count("grbd: "), 1, result.stderr)
            self.assertRegex(result.stderr, r"grbd: rank \d: .*o\.h5: .*failed")
            with h5py.File(out, "r") as f:  # the file holds every complete record: none
                self.assertEqual(int(f["records"].attrs["count"]), 0)
        finally:
            subprocess.run(["umount", folder], check=True)

    def test_the_parallel_table_is_checked_and_taken(self):
        with open(BALLISTIC) as f:
            text = f.read()
        for bad, key in (("rebalance_every = -1", "rebalance_every"),
                         ("imbalance = 0.5", "imbalance"), ("average_every = 0", "average_every"),
                         ("rebalance = 10", "unknown key"), ('partition = "tree"', "partition")):
            with open(self.path("bad.toml"), "w") as f:
                f.write(text + "\n[parallel]\n" + bad + "\n")
            result = grbd(2, "run", self.path("bad.toml"), "-o", self.path("bad.h5"), timeout=120)
            self.assertEqual(result.returncode, 3, result.stderr)
            self.assertEqual(result.stderr.count("grbd run:"), 1, result.stderr)
            self.assertIn("parallel", result.stderr)
            self.assertIn(key, result.stderr)
        # Averaging every third sweep and never rebalancing: free flight is still the serial run.
        with open(self.path("ok.toml"), "w") as f:
            f.write(text + "\n[parallel]\naverage_every = 3\nrebalance_every = 0\nimbalance = 2\n")
        self.run_ok(0, "run", self.path("ok.toml"), "-q", "-o", self.path("s.h5"), "-c",
                    self.path("s.c.h5"))
        self.run_ok(3, "run", self.path("ok.toml"), "-q", "-o", self.path("p.h5"), "-c",
                    self.path("p.c.h5"))
        self.assert_same_output(self.path("s.h5"), self.path("p.h5"))

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


class CollectiveFiles(Runs):
    """Output and checkpoints written by every process together (parallel HDF5), and checkpoints
    read in slabs: a file that does not tell how many processes wrote it, and damage found by the
    process that reads it, reported by all."""

    def pile_with_contacts(self):
        with open(PILE) as f:
            text = f.read()
        self.assertIn("[output]\n", text)
        scene = self.path("pile.toml")
        with open(scene, "w") as f:
            f.write(text.replace("[output]\n", "[output]\ncontacts = true\n"))
        return scene

    def test_every_process_writes_its_contacts_into_one_table_in_key_order(self):
        scene = self.pile_with_contacts()
        out, ckpt = self.path("c.h5"), self.path("c.c.h5")
        self.run_ok(3, "run", scene, "-q", "-o", out, "-c", ckpt, "--end-time", "0.1")
        with h5py.File(out, "r") as f:
            count = int(f["records"].attrs["count"])
            self.assertEqual(count, 6)
            steps = f["steps"][()]
            for k in range(count):
                record = f[f"records/{k:06d}"]
                ids = record["id"][()]
                self.assertTrue(np.all(np.diff(ids.astype(np.int64)) > 0), "ids ascending, once")
                self.assertEqual(len(ids), int(f["records/bodies"][k]))
                contacts = record["contacts"]
                keys = contacts["ids"][()]
                m = int(f["records/contacts"][k])
                self.assertEqual(len(keys), m)
                if k > 0:  # the record's contacts are the ones its step counted
                    self.assertEqual(m, int(steps["contacts"][int(record.attrs["step"]) - 1]))
                order = np.lexsort((keys[:, 1], keys[:, 0]))
                self.assertTrue(np.array_equal(order, np.arange(m)), "contacts in key order")
                self.assertTrue(np.array_equal(contacts["line_nodes"][()].ravel(),
                                               np.arange(2 * m)), "line nodes numbered globally")
                self.assertEqual(contacts["line"].shape, (2 * m, 3))
                # A line runs from side a's centre as detection saw it at the step's midpoint:
                # half a step (0.1 ms, under 0.1 mm at these speeds) from the record's centre.
                row = {int(i): n for n, i in enumerate(ids)}
                centres = record["I_r_S"][()]
                for j in range(0, m, max(1, m // 50)):
                    a = int(keys[j, 0])
                    if a in row:
                        np.testing.assert_allclose(contacts["line"][2 * j], centres[row[a]],
                                                   rtol=0, atol=1e-4)
            self.assertGreater(int(f["records/contacts"][count - 1]), 100)

    def test_a_damaged_checkpoint_is_refused_by_every_process_with_one_message(self):
        out, ckpt = self.path("d.h5"), self.path("d.c.h5")
        self.run_ok(2, "run", PILE, "-q", "-o", out, "-c", ckpt, "--end-time", "0.02")
        with h5py.File(ckpt, "r+") as f:  # a bit in the last row: the last process's slab
            states = f["states"]
            states[len(states) - 1, 3] = np.nextafter(states[len(states) - 1, 3], 2.0)
        result = grbd(3, "run", PILE, "-q", "-o", out, "-c", self.path("e.c.h5"), "-r", ckpt,
                      "--end-time", "0.04")
        self.assertNotEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stderr.count("is damaged"), 1, result.stderr)
        self.assertNotIn("rank", result.stderr.split("is damaged")[0])
        self.assertFalse(os.path.exists(self.path("e.c.h5")))

    def test_a_checkpoint_of_3_processes_restarts_on_2_with_its_warm_starts(self):
        out, ckpt = self.path("w.h5"), self.path("w.c.h5")
        self.run_ok(3, "run", PILE, "-q", "-o", out, "-c", ckpt, "--end-time", "0.1")
        with h5py.File(ckpt, "r") as f:
            keys = f["warm_start_keys"][()]
            lambdas = f["warm_start_lambda"][()]
            ids = f["bodies"]["id"][()]
            states = f["states"][()]
        self.assertGreater(len(keys), 100)
        self.assertTrue(np.all(np.diff(ids.astype(np.int64)) > 0))
        # Restarted without a step, the checkpoint written again holds the same rows: every body
        # and every warm start went to a process (its owner, its solver) and came back once.
        again = self.path("w2.c.h5")
        self.run_ok(2, "run", PILE, "-q", "-o", self.path("w2.h5"), "-c", again, "-r", ckpt,
                    "--end-time", "0.1")
        with h5py.File(again, "r") as f:
            self.assertTrue(np.array_equal(f["warm_start_keys"][()], keys))
            self.assertTrue(np.array_equal(f["warm_start_lambda"][()], lambdas))
            self.assertTrue(np.array_equal(f["bodies"]["id"][()], ids))
            self.assertTrue(np.array_equal(f["states"][()], states))
        # A version 3 checkpoint (keys without their image column; the same checksum, since a key
        # without an image adds nothing to it) restarts alike and is written again as version 4.
        old = self.path("w.v3.c.h5")
        shutil.copyfile(ckpt, old)
        with h5py.File(old, "r+") as f:
            self.assertEqual(int(f.attrs["format_version"]), 4)
            self.assertTrue(np.all(keys[:, 4] == 0))
            del f["warm_start_keys"]
            f.create_dataset("warm_start_keys", data=keys[:, :4])
            f.attrs["format_version"] = np.uint64(3)
        self.run_ok(2, "run", PILE, "-q", "-o", self.path("w5.h5"), "-c", self.path("w5.c.h5"),
                    "-r", old, "--end-time", "0.1")
        with h5py.File(self.path("w5.c.h5"), "r") as f:
            self.assertTrue(np.array_equal(f["warm_start_keys"][()], keys))
            self.assertEqual(int(f.attrs["format_version"]), 4)
        # and continued, the first step finds its contacts warm-started as the serial restart does
        self.run_ok(2, "run", PILE, "-q", "-o", self.path("w3.h5"), "-c", self.path("w3.c.h5"),
                    "-r", ckpt, "--end-time", "0.1002")
        self.run_ok(0, "run", PILE, "-q", "-o", self.path("w4.h5"), "-c", self.path("w4.c.h5"),
                    "-r", ckpt, "--end-time", "0.1002")
        with h5py.File(self.path("w3.h5"), "r") as f3, h5py.File(self.path("w4.h5"), "r") as f4:
            parallel, serial = f3["steps"][()][-1], f4["steps"][()][-1]
        self.assertEqual(parallel["contacts"], serial["contacts"])
        self.assertEqual(parallel["warm_started"], serial["warm_started"])


class Chute(Runs):
    """The tiny chute end to end (data/tiny_chute.toml): 400 beads behind a gate that opens at
    0.05 s flow past the kink at x = -0.296 m and out through the outlet at x = -0.6 m."""

    RELEASE, KINK, OUTLET = 0.05, -0.296, -0.6

    def run_chute(self, p):
        scene = os.path.join(os.path.dirname(BALLISTIC), "tiny_chute.toml")
        out, ckpt, csv = self.path(f"c{p}.h5"), self.path(f"c{p}.c.h5"), self.path(f"c{p}.csv")
        self.run_ok(p, "run", scene, "-q", "-o", out, "-c", ckpt)
        result = self.run_ok(0, "chute", out, "--csv", csv)
        return out, ckpt, csv, result.stdout

    def test_the_tiny_chute_keeps_every_bead_and_measures_its_flow(self):
        entries = []
        for p in (0, 2, 3):
            out, ckpt, csv, report = self.run_chute(p)
            with h5py.File(out, "r") as f, h5py.File(ckpt, "r") as c:
                mass = dict(zip(f["bodies"]["id"][()].tolist(), f["bodies"]["mass"][()].tolist()))
                first = f["records/000000/id"][()]
                self.assertEqual(len(first), 400)
                n = int(f["records"].attrs["count"])
                counts, previous = [], None
                for k in range(n):
                    r = f[f"records/{k:06d}"]
                    ids, x = r["id"][()], r["I_r_S"][()]
                    self.assertEqual(len(np.unique(ids)), len(ids), f"P = {p}: a bead twice")
                    self.assertTrue(set(ids.tolist()) <= set(first.tolist()), f"P = {p}")
                    if previous is not None:  # a bead that is gone left through the outlet
                        gone = np.isin(previous[0], ids, invert=True)
                        self.assertTrue(np.all(previous[1][gone, 0] < self.OUTLET + 0.1),
                                        f"P = {p}: a bead lost upstream of the outlet")
                    previous = (ids, x)
                    counts.append(int(np.sum(x[:, 0] < self.KINK)) + 400 - len(ids))
                # The mass that left through the outlet and the mass still there are the mass
                # of the 400 beads.
                total = sum(mass[i] for i in first.tolist())
                left = sum(mass[i] for i in previous[0].tolist()) + float(c.attrs["removed_mass"])
                self.assertAlmostEqual(left, total, delta=1e-12 * total)
            data = np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2)
            # grbd chute's flow count is the count of the file's positions, record by record
            self.assertTrue(np.array_equal(data[:, 2], counts), f"P = {p}")
            self.assertTrue(np.all(np.diff(data[:, 2]) >= 0), "F(t) never decreases")
            self.assertEqual(data[-1, 2], 400.0)  # every bead past the kink by 0.7 s
            # The front reaches the kink (0.296 m down the upper chute) between the times of a
            # frictionless bead sliding from the gate, sqrt(2 L / (g sin 30°)) = 0.347 s, and of
            # a bead rolling without slipping, sqrt(2 L / (5/7 g sin 30°)) = 0.411 s, after the
            # release — with room for the column's collapse at the gate.
            arrive = data[np.argmax(data[:, 3] >= -self.KINK), 0] - self.RELEASE
            self.assertGreater(arrive, 0.30, f"P = {p}")
            self.assertLess(arrive, 0.46, f"P = {p}")
            entry = float(re.search(r"entry \(150 beads past the kink\): ([0-9.]+) s",
                                    report).group(1))
            entries.append(entry)
        # Two or three processes do not step bit for bit as one (contacts solved in another
        # order), but the flow arrives at the same time, to a record's spacing.
        for entry in entries[1:]:
            self.assertLess(abs(entry - entries[0]), 0.02, entries)


    def test_grbd_chute_refuses_what_is_not_an_output_and_keeps_an_earlier_csv(self):
        csv = self.path("flow.csv")
        with open(csv, "w") as f:
            f.write("an earlier result\n")
        result = grbd(0, "chute", BALLISTIC, "--csv", csv)  # a scene, not an output
        self.assertEqual(result.returncode, 3, result.stderr)
        self.assertIn("grbd chute: ", result.stderr)
        self.assertIn("ballistic.toml", result.stderr)
        with open(csv) as f:
            self.assertEqual(f.read(), "an earlier result\n")
        out, _, _, _ = self.run_chute(0)
        result = grbd(0, "chute", out, "--csv", os.path.join(self.dir, "none", "flow.csv"))
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("does not exist", result.stderr)
        for bad in (["--entry", "0"], ["--entry", "nan"], ["--kink", "nan"], ["--wrong"]):
            result = grbd(0, "chute", out, *bad)
            self.assertEqual(result.returncode, 2, (bad, result.stderr))


    def test_the_cluster_script_stops_before_its_time_limit_and_goes_on(self):
        # chapters/08-parallel-chute-flow/chute_full.slurm outside SLURM, on the tiny chute: a time
        # limit of 3 s, so that the stop file comes at 2.25 s (a quarter before the limit), then
        # the same script again, which restarts from the checkpoint and finishes.
        script = os.path.abspath(os.path.join(os.path.dirname(PILE), "..", "..", "chapters",
                                              "08-parallel-chute-flow", "chute_full.slurm"))
        scene = os.path.abspath(os.path.join(os.path.dirname(BALLISTIC), "tiny_chute.toml"))
        env = dict(os.environ, GRBD=os.path.abspath(GRBD), GRBD_PROCESSES="2", GRBD_SECONDS="3",
                   GRBD_SCENE=scene)
        first = subprocess.run(["bash", script], cwd=self.dir, env=env, capture_output=True,
                               text=True, timeout=300)
        self.assertIn(first.returncode, (0, 4), first.stdout + first.stderr)  # 0: a fast machine
        if first.returncode == 4:
            self.assertIn("submit again", first.stdout)
            self.assertTrue(os.path.exists(self.path("tiny_chute.ckpt.h5")))
            del env["GRBD_SECONDS"]
            second = subprocess.run(["bash", script], cwd=self.dir, env=env, capture_output=True,
                                    text=True, timeout=300)
            self.assertEqual(second.returncode, 0, second.stdout + second.stderr)
        result = self.run_ok(0, "chute", self.path("tiny_chute.h5"))
        self.assertIn("beads past the kink at the end: 400 (100 %)", result.stdout)


class Incline(Runs):
    """The tiny incline end to end (data/tiny_incline.toml): 150 beads on a base of 16 fixed ones
    in a box periodic along and across the flow, tilted 24°, serially and on 2 and 3 processes."""

    L, THETA, G, BEADS, BASE = 0.0092, math.radians(24.0), 9.81, 150, 16

    def test_the_tiny_incline_keeps_every_bead_and_starts_to_flow(self):
        scene = os.path.join(os.path.dirname(BALLISTIC), "tiny_incline.toml")
        speeds, heights = [], []
        for p in (0, 2, 3):
            out = self.path(f"i{p}.h5")
            self.run_ok(p, "run", scene, "-q", "-o", out, "-c", self.path(f"i{p}.c.h5"))
            with h5py.File(out, "r") as f:
                fixed = f["bodies"]["fixed"][()].astype(bool)
                self.assertEqual(int(fixed.sum()), self.BASE)
                base = f["bodies"]["id"][()][fixed]
                first = f["records/000000"]
                base_x = first["I_r_S"][()][np.isin(first["id"][()], base)]
                n = int(f["records"].attrs["count"])
                for k in range(n):
                    r = f[f"records/{k:06d}"]
                    ids, x, v = r["id"][()], r["I_r_S"][()], r["I_v_S"][()]
                    t = float(r.attrs["time"])
                    # Every bead once, none lost: the box has no outlet along x and y.
                    self.assertTrue(np.array_equal(np.sort(ids), np.arange(self.BEADS + self.BASE)),
                                    f"P = {p}, t = {t}")
                    # Wrapped into the periodic cell (to within the skin: a body is wrapped when
                    # the neighbour lists are rebuilt).
                    self.assertTrue(np.all((x[:, :2] > -1e-3) & (x[:, :2] < self.L + 1e-3)),
                                    f"P = {p}")
                    on_base = np.isin(ids, base)
                    # The base does not move.
                    self.assertTrue(np.array_equal(x[on_base], base_x), f"P = {p}, t = {t}")
                    # No faster than a frictionless fall along the slope from rest.
                    mean = float(v[~on_base, 0].mean())
                    self.assertLessEqual(mean, self.G * math.sin(self.THETA) * t + 1e-12)
                # At 24° the layer flows (glass beads stop below about 21°): downstream, and
                # never backwards.
                self.assertGreater(mean, 0.02, f"P = {p}")
                # The speed over the second half of the run. The onset of a flow of 150 beads is
                # chaotic: a change in the order the contacts are solved in (another partition,
                # a balance, a Morton reordering) moves one record's speed at 0.3 s between 0.033
                # and 0.10 m/s, the mean over the second half between 0.054 and 0.091 m/s.
                speeds.append(float(np.mean([
                    f[f"records/{k:06d}/I_v_S"][()][
                        ~np.isin(f[f"records/{k:06d}/id"][()], base), 0].mean()
                    for k in range(n // 2, n)])))
                heights.append(float(x[~on_base, 2].mean()))
        # Two or three processes that balance their loads do not step bit for bit as one
        # (contacts solved in another order, split beads averaged), and the onset of a flow
        # amplifies the difference: the layers settle to the same height to 2 %, and flow at mean
        # speeds within a factor of two of one another (a layer that locked or ran away would not).
        for height in heights[1:]:
            self.assertLess(abs(height - heights[0]), 0.02 * heights[0], heights)
        self.assertLess(max(speeds), 2.0 * min(speeds), speeds)


class Periodic(Runs):
    """A periodic box is the central cell of the box tiled 3 × 3 with its copies."""

    L = 0.04  # the period along x and y [m]

    def gas(self):
        """16 spheres of radius 2 mm in a layer, with random velocities in the plane."""
        rng = np.random.default_rng(4)
        centres, r = [], 0.002
        while len(centres) < 16:
            c = rng.uniform(0.0, self.L, 2)
            d = [np.linalg.norm((c - o) - self.L * np.round((c - o) / self.L)) for o in centres]
            if all(x > 2.5 * r for x in d):
                centres.append(c)
        velocities = rng.uniform(-0.4, 0.4, (16, 2))
        return np.array(centres), velocities, r

    def scene(self, name, tiles, periodic):
        centres, velocities, r = self.gas()
        text = ("[simulation]\ndt = 1e-3\nend_time = 0.05\ngravity = [0.0, 0.0, 0.0]\n")
        if periodic:
            text += (f"domain = {{ min = [0.0, 0.0, -0.01], max = [{self.L}, {self.L}, 0.01] }}\n"
                     'periodic = ["x", "y"]\n')
        text += ('[solver]\nmethod = "sor"\ntolerance = 1e-12\nmax_iterations = 200\n'
                 '[[material]]\nname = "glass"\n[[contact]]\nmaterials = ["glass", "glass"]\n'
                 "mu = 0.0\neps_N = 1.0\n")
        # The central copies first, so that their ids are 0 … 15 in both scenes.
        for i, j in tiles:
            for k, (c, v) in enumerate(zip(centres, velocities)):
                x, y = c[0] + i * self.L, c[1] + j * self.L
                text += (f'[[bodies]]\nname = "b{i}{j}_{k}"\nradius = {r}\ndensity = 2500.0\n'
                         f'material = "glass"\nvelocity = [{v[0]!r}, {v[1]!r}, 0.0]\n'
                         f"positions = [[{x!r}, {y!r}, 0.0]]\n")
        text += "[output]\nevery = 1\ncontacts = true\n"
        with open(self.path(name), "w") as f:
            f.write(text)
        return self.path(name)

    def last(self, path, n=16):
        with h5py.File(path, "r") as f:
            last = f["records/%06d" % (int(f["records"].attrs["count"]) - 1)]
            ids = last["id"][()]
            order = np.argsort(ids)[:n]
            self.assertTrue(np.array_equal(ids[order], np.arange(n)))
            contacts = int(f["steps"]["contacts"].sum())
            return last["I_r_S"][()][order], last["I_v_S"][()][order], contacts

    def test_a_periodic_box_is_the_central_cell_of_the_tiled_box(self):
        tiles = [(0, 0)] + [(i, j) for i in (-1, 0, 1) for j in (-1, 0, 1) if (i, j) != (0, 0)]
        tiled = self.scene("tiled.toml", tiles, periodic=False)
        self.run_ok(0, "run", tiled, "-q", "-o", self.path("t.h5"), "-c", self.path("t.c.h5"))
        x_ref, v_ref, _ = self.last(self.path("t.h5"))
        with h5py.File(self.path("t.h5"), "r") as f:  # central bodies touched their images' copies
            across = sum(int(np.sum((ids.min(axis=1) < 16) & (ids.max(axis=1) >= 16)))
                         for ids in (f["records/%06d/contacts/ids" % k][()]
                                     for k in range(int(f["records"].attrs["count"]))))
        self.assertGreater(across, 0, "no contact across the boundary: nothing was tested")
        box = self.scene("box.toml", [(0, 0)], periodic=True)
        for p in (0, 2, 3):  # the parallel engine on one process (no mpiexec), on two and three
            out = self.path(f"p{p}.h5")
            self.run_ok(p, "run", box, "-q", "-o", out, "-c", self.path(f"p{p}.c.h5"))
            x, v, contacts = self.last(out)
            self.assertGreater(contacts, 10, "the gas must collide, also across the boundary")
            d = (x - x_ref)[:, :2]
            d -= self.L * np.round(d / self.L)  # the same place, up to a period
            self.assertLess(np.abs(d).max(), 1e-9, f"P = {p}")
            # the velocities to 2.5e-7 of the speeds: what the solver's tolerance leaves of each impact,
            # grown by the collisions that follow
            self.assertLess(np.abs(v - v_ref).max(), 1e-7, f"P = {p}")
            # wrapped into the box, up to what a body moves between two rebuilds of the ghosts
            self.assertTrue(np.all((x[:, :2] > -1e-3) & (x[:, :2] < self.L + 1e-3)), x)

    def test_momentum_is_conserved_across_the_periodic_boundary(self):
        box = self.scene("box.toml", [(0, 0)], periodic=True)
        out = self.path("m.h5")
        self.run_ok(2, "run", box, "-q", "-o", out, "-c", self.path("m.c.h5"))
        with h5py.File(out, "r") as f:
            mass = f["bodies"]["mass"][()]
            count = int(f["records"].attrs["count"])
            p = [mass @ f["records/%06d/I_v_S" % k][()] for k in range(count)]
            scale = mass @ np.linalg.norm(f["records/000000/I_v_S"][()], axis=1)
        self.assertLess(np.abs(np.array(p) - p[0]).max(), 1e-13 * scale)

    def test_bad_periodic_scenes_are_refused_naming_the_key(self):
        box = self.scene("box.toml", [(0, 0)], periodic=True)
        with open(box) as f:
            text = f.read()
        for wrong, expected in (('periodic = ["x", "y"]', None),
                                ('periodic = ["x", "x"]', "distinct axis names"),
                                ('periodic = ["w"]', "distinct axis names"),
                                ('periodic = "x"', "distinct axis names")):
            bad = text.replace('periodic = ["x", "y"]', wrong)
            if expected is None:  # periodic without a domain
                bad = "\n".join(line for line in text.splitlines()
                                if not line.startswith("domain"))
                expected = "the periodic box"
            with open(self.path("bad.toml"), "w") as f:
                f.write(bad)
            result = grbd(0, "run", self.path("bad.toml"), "-o", self.path("bad.h5"))
            self.assertEqual(result.returncode, 3, result.stderr)
            self.assertIn("periodic", result.stderr)
            self.assertIn(expected, result.stderr)
        narrow = text.replace(f"max = [{self.L}, {self.L}, 0.01]", f"max = [0.004, {self.L}, 0.01]")
        with open(self.path("narrow.toml"), "w") as f:
            f.write(narrow)
        result = grbd(0, "run", self.path("narrow.toml"), "-o", self.path("n.h5"))
        self.assertEqual(result.returncode, 3, result.stderr)
        self.assertIn("expected more than the reach of a contact", result.stderr)

    def test_two_spheres_touching_directly_and_through_the_boundary_are_two_contacts(self):
        # A period of four radii: A touches B on its right and B's image on its left, an endless
        # chain. A and B approach at 2v; with eps_N = 1 they swap velocities at every step (the
        # contact that closes takes 2 m v more than the other), and Moreau's midpoint brings every
        # sphere back to where it started. With an active-set margin of r/100 both contacts are
        # active at every step, and their keys differ only by the image: two warm starts.
        r, v = 0.002, 0.01
        text = ("[simulation]\ndt = 1e-3\nend_time = 0.01\ngravity = [0.0, 0.0, 0.0]\n"
                f"domain = {{ min = [0.0, -0.01, -0.01], max = [{4 * r}, 0.01, 0.01] }}\n"
                'periodic = ["x"]\n[solver]\nmethod = "sor"\ntolerance = 1e-12\n'
                'max_iterations = 200\ncontact_tolerance = 0.01\n[[material]]\nname = "glass"\n'
                '[[contact]]\nmaterials = ["glass", "glass"]\nmu = 0.0\neps_N = 1.0\n')
        for name, x, u in (("a", r, v), ("b", 3 * r, -v)):
            text += (f'[[bodies]]\nname = "{name}"\nradius = {r}\ndensity = 2500.0\n'
                     f'material = "glass"\nvelocity = [{u}, 0.0, 0.0]\n'
                     f"positions = [[{x}, 0.0, 0.0]]\n")
        text += "[output]\nevery = 1\ncontacts = true\n"
        scene = self.path("chain.toml")
        with open(scene, "w") as f:
            f.write(text)
        mass = 2500.0 * 4.0 / 3.0 * np.pi * r**3
        for p in (0, 2, 3):
            out, ckpt = self.path(f"chain{p}.h5"), self.path(f"chain{p}.c.h5")
            self.run_ok(p, "run", scene, "-q", "-o", out, "-c", ckpt)
            with h5py.File(out, "r") as f:
                steps = f["steps"]
                self.assertTrue(np.all(steps["contacts"][()] == 2), f"P = {p}")
                self.assertTrue(np.all(steps["warm_started"][1:] == 2), f"P = {p}")
                for k in range(1, 11):
                    record = f[f"records/{k:06d}"]
                    order = np.argsort(record["id"][()])
                    sign = -1.0 if k % 2 == 1 else 1.0  # A turns back at every odd step
                    np.testing.assert_allclose(record["I_v_S"][()][order, 0],
                                               [sign * v, -sign * v], rtol=1e-5, atol=0)
                    np.testing.assert_allclose(record["I_r_S"][()][order, 0], [r, 3 * r],
                                               rtol=0, atol=1e-10)
                    lam = record["contacts"]["lambda_N"][()]
                    self.assertEqual(len(lam), 2)
                    self.assertAlmostEqual(lam.max() - lam.min(), 2 * mass * v,
                                           delta=1e-5 * mass * v)
            with h5py.File(ckpt, "r") as f:
                keys = f["warm_start_keys"][()]
                self.assertEqual(keys.shape, (2, 5))
                self.assertEqual(sorted(int(k) for k in keys[:, 4]), [0, 13])  # B and B − L

if __name__ == "__main__":
    GRBD, MPIEXEC, BALLISTIC, PILE = sys.argv[1:5]
    unittest.main(argv=sys.argv[:1] + sys.argv[5:], verbosity=2)
