#!/usr/bin/env python3
"""What a fault campaign found in chapter 8's runs, each as a test of `grbd run` and `grbd chute`
on one process and under mpiexec: the stop file is none of the run's files and a fresh one is
never taken as stale; an error only one process meets (its scene, its options) ends the job with
one message; a full disk ends every process with exit code 1 and leaves files that open; one
message per job; `grbd chute --csv` replaces only a regular file that is none of the run's; a
method other than SOR runs on one process and is refused, with one message, on two.

Usage: test_run_faults.py GRBD MPIEXEC TINY_CHUTE [unittest options]. Needs python3 and h5py."""

import fcntl
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

import h5py

GRBD = MPIEXEC = CHUTE = None
os.environ.update({"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
                   "OMPI_MCA_btl": "self,vader,tcp", "OMPI_MCA_mpi_yield_when_idle": "1",
                   "OMPI_MCA_rmaps_base_oversubscribe": "1"})
LAUNCH = ["--oversubscribe", "--bind-to", "none"]


def grbd(processes, *args, timeout=180, cwd=None):
    """grbd serially (processes = 0: no mpiexec) or under mpiexec with that many processes."""
    launcher = [] if processes == 0 else [MPIEXEC, "-n", str(processes), *LAUNCH]
    return subprocess.run([*launcher, GRBD, *args], capture_output=True, text=True,
                          timeout=timeout, cwd=cwd)


def messages(stderr):
    """grbd's own lines of a job's stderr (mpiexec's banners left out)."""
    return [line for line in stderr.splitlines() if line.startswith("grbd")]


class Faults(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="grbd-faults-")
        self.addCleanup(shutil.rmtree, self.dir, ignore_errors=True)
        self.scene = self.path("k.toml")
        shutil.copy(CHUTE, self.scene)

    def path(self, name):
        return os.path.join(self.dir, name)

    def size(self, name):
        return os.path.getsize(self.path(name)) if os.path.exists(self.path(name)) else None

    def test_the_stop_file_is_none_of_the_runs_files(self):
        for p in (0, 2):
            o, c = f"o{p}.h5", f"c{p}.h5"
            result = grbd(p, "run", self.scene, "-q", "-o", self.path(o), "-c", self.path(c),
                          "--end-time", "0.004")
            self.assertEqual(result.returncode, 0, result.stderr)
            before = {name: self.size(name) for name in (o, c, "k.toml")}
            restart = ["-o", self.path(o), "-c", self.path(c), "-r", self.path(c)]
            for stop, args in ((o, restart), (c, restart), ("k.toml", restart),
                               (o.replace(".h5", ".xmf"), restart),
                               ("n.h5", ["-o", self.path("n.h5"), "-c", self.path("n.c.h5")]),
                               ("n.c.h5", ["-o", self.path("n.h5"), "-c", self.path("n.c.h5")])):
                result = grbd(p, "run", self.scene, "-q", *args, "--end-time", "0.006",
                              "--stop-file", self.path(stop))
                self.assertEqual(result.returncode, 2, (p, stop, result.stderr))
                lines = messages(result.stderr)
                self.assertEqual(len(lines), 1, result.stderr)
                self.assertIn("the stop file", lines[0])
                self.assertIn("it would be removed", lines[0])
                self.assertEqual({name: self.size(name) for name in before}, before, stop)
                self.assertFalse(os.path.exists(self.path("n.h5")))
            # A folder is no stop file: it is refused, not taken as a request to stop.
            os.mkdir(self.path(f"folder{p}"))
            result = grbd(p, "run", self.scene, "-q", *restart, "--stop-file",
                          self.path(f"folder{p}"))
            self.assertEqual(result.returncode, 2, result.stderr)
            self.assertIn("a folder", result.stderr)
            self.assertTrue(os.path.isdir(self.path(f"folder{p}")))

    def test_a_stop_file_from_before_the_start_is_stale_and_a_newer_one_stops_the_run(self):
        for p in (0, 2):
            stop = self.path(f"s{p}.stop")
            args = ["run", self.scene, "-q", "-o", self.path(f"s{p}.h5"), "-c",
                    self.path(f"s{p}.c.h5"), "--end-time", "0.004", "--stop-file", stop]
            # Left by a run killed a minute ago: removed with a warning, and the run goes on.
            open(stop, "w").close()
            os.utime(stop, (time.time() - 60, time.time() - 60))
            result = grbd(p, *args)
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertIn("removed the stop file that an earlier run left", result.stderr)
            self.assertFalse(os.path.exists(stop))
            # Touched after the start (here: dated a minute ahead, as a touch during the first
            # second would be): a request to stop at the first step boundary, honoured.
            open(stop, "w").close()
            os.utime(stop, (time.time() + 60, time.time() + 60))
            result = grbd(p, *args, "--force")
            self.assertNotEqual(result.returncode, 0, result.stderr)
            if p == 0:
                self.assertEqual(result.returncode, 4, result.stderr)
            self.assertFalse(os.path.exists(stop), "the stop file is removed once honoured")
            with h5py.File(self.path(f"s{p}.c.h5"), "r") as f:
                self.assertEqual(int(f.attrs["steps"]), 0)

    def test_an_error_that_one_process_meets_before_the_run_ends_the_job_with_one_message(self):
        # mpiexec's MPMD syntax gives rank 1 its own folder and command line.
        a, b = self.path("A"), self.path("B")
        os.mkdir(a)
        os.mkdir(b)
        with open(CHUTE) as f:
            text = f.read()
        with open(os.path.join(a, "s.toml"), "w") as f:
            f.write(text)

        def job(scene_b, end_a="0.002", end_b="0.002"):
            with open(os.path.join(b, "s.toml"), "w") as f:
                f.write(scene_b)
            common = ["run", "s.toml", "-q", "-o", self.path("o.h5"), "-c", self.path("c.h5")]
            start = time.monotonic()
            result = subprocess.run(
                [MPIEXEC, *LAUNCH, "-n", "1", "--wdir", a, GRBD, *common, "--end-time", end_a,
                 ":", "-n", "1", "--wdir", b, GRBD, *common, "--end-time", end_b],
                capture_output=True, text=True, timeout=120)
            self.assertLess(time.monotonic() - start, 60, "the job hung")
            return result

        bad = text.replace("\ndt = ", "\ndt = -1 # ", 1)
        self.assertNotEqual(bad, text)
        for result, code, words in (
                (job(bad), 3, ["rank 1: ", "s.toml", "dt"]),
                (job(text, end_b="0.0x"), 2, ["rank 1: ", "--end-time", "0.0x"]),
                (job(text, end_b="0.004"), 2, ["rank 1: ", "end time", "differs from rank 0's"]),
                (job(text + "\n# another scene\n"), 2, ["rank 1: ", "scene differs"])):
            self.assertEqual(result.returncode, code, result.stderr)
            lines = messages(result.stderr)
            self.assertEqual(len(lines), 1, result.stderr)
            for word in words:
                self.assertIn(word, lines[0])
            self.assertFalse(os.path.exists(self.path("o.h5")), "nothing is written")

    def test_a_method_other_than_sor_runs_on_one_process_and_is_refused_on_two(self):
        # Split bodies need SOR's averaging between sweeps; one process splits nothing (periodic
        # images are folded onto their owners), so it runs any method.
        with open(CHUTE) as f:
            text = f.read()
        apgd = text.replace('method = "sor"', 'method = "apgd"', 1)
        self.assertNotEqual(apgd, text)
        with open(self.scene, "w") as f:
            f.write(apgd)
        result = grbd(0, "run", self.scene, "-q", "-o", self.path("a.h5"), "-c",
                      self.path("a.c.h5"), "--end-time", "0.002")
        self.assertEqual(result.returncode, 0, result.stderr)
        result = grbd(2, "run", self.scene, "-q", "-o", self.path("b.h5"), "-c",
                      self.path("b.c.h5"), "--end-time", "0.002")
        self.assertEqual(result.returncode, 3, result.stderr)
        lines = messages(result.stderr)
        self.assertEqual(len(lines), 1, result.stderr)
        for word in ("k.toml", "method APGD on 2 processes", "SOR"):
            self.assertIn(word, lines[0])
        self.assertFalse(os.path.exists(self.path("b.h5")), "nothing is written")

    def mount_small_disk(self, name):
        folder = self.path(name)
        os.mkdir(folder)
        mount = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=300k", "tmpfs", folder],
                               capture_output=True) if os.geteuid() == 0 else None
        if mount is None or mount.returncode != 0:
            self.skipTest("needs root and a tmpfs mount (a full disk of 300 KiB)")
        self.addCleanup(subprocess.run, ["umount", folder], check=True)
        return folder

    def test_an_output_on_a_full_disk_ends_every_process_and_still_opens(self):
        small = self.mount_small_disk("small")
        for p in (3, 4):
            out = os.path.join(small, f"o{p}.h5")
            start = time.monotonic()
            result = grbd(p, "run", self.scene, "-q", "-o", out, "-c", self.path(f"c{p}.h5"),
                          timeout=150)
            self.assertLess(time.monotonic() - start, 60, "no hang in the collective close")
            self.assertEqual(result.returncode, 1, result.stderr)
            self.assertEqual(len(messages(result.stderr)), 1, result.stderr)
            self.assertRegex(result.stderr, r"o\d\.h5: .*failed")
            with h5py.File(out, "r") as f:  # every complete record: none fits
                self.assertEqual(int(f["records"].attrs["count"]), 0)
            os.remove(out)

    def test_a_checkpoint_on_a_full_disk_ends_with_exit_1_and_keeps_the_previous_one(self):
        small = self.mount_small_disk("small")
        ckpt = os.path.join(small, "c.h5")
        for p in (2, 3):
            for name in os.listdir(small):
                os.remove(os.path.join(small, name))
            process = subprocess.Popen(
                [MPIEXEC, "-n", str(p), *LAUNCH, GRBD, "run", self.scene, "-q", "-o",
                 self.path(f"o{p}.h5"), "-c", ckpt, "--force"],
                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            deadline = time.monotonic() + 60
            while not os.path.exists(ckpt) and time.monotonic() < deadline:
                time.sleep(0.02)
            self.assertTrue(os.path.exists(ckpt), "no first checkpoint")
            # Fill the disk: the next checkpoint's write fails.
            free = os.statvfs(small)
            with open(os.path.join(small, "filler"), "wb") as f:
                try:
                    f.write(b"\0" * (free.f_bavail * free.f_frsize))
                except OSError:
                    pass
            _, stderr = process.communicate(timeout=150)
            self.assertEqual(process.returncode, 1, stderr)  # not 139: no crash in MPI_Finalize
            self.assertEqual(len(messages(stderr)), 1, stderr)
            self.assertIn("c.h5", stderr)
            os.remove(os.path.join(small, "filler"))
            with h5py.File(ckpt, "r") as f:  # the previous checkpoint, whole
                self.assertGreater(int(f.attrs["steps"]), 0)
            result = grbd(0, "run", self.scene, "-q", "-o", self.path(f"o{p}.h5"), "-c",
                          self.path(f"r{p}.h5"), "-r", ckpt, "--end-time", "0.01")
            self.assertEqual(result.returncode, 0, result.stderr)

    def test_a_restart_on_as_many_processes_continues_the_run_bit_for_bit_after_balances(self):
        # The balance looks at the load every 50 steps and moves the cuts (the default table);
        # the checkpoint at step 60 keeps them, and every checkpoint leaves each body with its
        # owner, so that the restart steps as the run goes on.
        with open(self.scene) as f:
            text = f.read()
        scene = self.path("b.toml")
        with open(scene, "w") as f:
            f.write(text + "\n[parallel]\nrebalance_every = 50\nimbalance = 1.05\n")
        for p in (2, 3):
            ref, out, ckpt = self.path(f"ref{p}.h5"), self.path(f"s{p}.h5"), self.path(f"s{p}.c.h5")
            result = grbd(p, "run", scene, "-o", ref, "-c", self.path(f"ref{p}.c.h5"))
            self.assertEqual(result.returncode, 0, result.stderr)
            self.assertRegex(result.stdout, r"[1-9]\d* rebalances", "nothing was tested")
            for args in (["--end-time", "0.012"], ["-r", ckpt]):
                result = grbd(p, "run", scene, "-q", "-o", out, "-c", ckpt, *args)
                self.assertEqual(result.returncode, 0, result.stderr)
            with h5py.File(ref, "r") as a, h5py.File(out, "r") as b:
                count = int(a["records"].attrs["count"])
                self.assertEqual(int(b["records"].attrs["count"]), count)
                for k in range(count):
                    for name in ("id", "I_r_S", "p", "I_v_S", "K_omega"):
                        path = f"records/{k:06d}/{name}"
                        self.assertTrue((a[path][()] == b[path][()]).all(), f"P = {p}: {path}")
            with h5py.File(ckpt, "r") as f:  # the cuts: processes, kind, boundaries
                self.assertEqual(f["distribution"][0], p)

    def test_one_message_a_job(self):
        result = grbd(2, "validate", self.scene)
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(result.stdout.count("\nok\n") + result.stdout.startswith("ok\n"), 1,
                         result.stdout)
        result = grbd(2, "run", self.path("missing.toml"))
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertEqual(len(messages(result.stderr)), 1, result.stderr)
        result = grbd(3, "run", self.scene, "--wrong-option")
        self.assertEqual(len(messages(result.stderr)), 1, result.stderr)

    def test_grbd_chute_replaces_only_a_regular_file_that_is_none_of_the_runs(self):
        out = self.path("o.h5")
        result = grbd(0, "run", self.scene, "-q", "-o", out, "-c", self.path("c.h5"),
                      "--end-time", "0.004")
        self.assertEqual(result.returncode, 0, result.stderr)
        size = os.path.getsize(out)
        os.mkfifo(self.path("fifo"))
        os.mkdir(self.path("folder"))
        with open(self.path("earlier.csv"), "w") as f:
            f.write("an earlier result\n")
        os.chmod(self.path("earlier.csv"), 0o444)
        shutil.copy(self.scene, self.path("copy.toml"))  # a file of the user's, not a table
        bad = [out, os.path.join(self.dir, ".", "o.h5"), self.path("o.xmf"), self.scene,
               self.path("fifo"), self.path("folder"), "", self.path("none/flow.csv"),
               self.path("copy.toml")]
        if os.geteuid() != 0:  # root writes a read-only file all the same
            bad.append(self.path("earlier.csv"))
        for csv in bad:
            result = grbd(0, "chute", out, "--csv", csv, cwd=self.dir)
            self.assertEqual(result.returncode, 2, (csv, result.stderr))
            self.assertIn("--csv", result.stderr)
            self.assertNotIn("Success", result.stderr)
            self.assertEqual(os.path.getsize(out), size)
        self.assertTrue(os.path.exists(self.scene))
        self.assertFalse(os.path.isfile(self.path("fifo")))
        with open(self.path("copy.toml")) as f, open(self.scene) as g:
            self.assertEqual(f.read(), g.read())
        for _ in range(2):  # a new table, then the earlier table replaced
            result = grbd(0, "chute", out, "--csv", self.path("flow.csv"))
            self.assertEqual(result.returncode, 0, result.stderr)
            with open(self.path("flow.csv")) as f:
                self.assertEqual(f.readline(), "t_s,bodies,flow_count,front_m\n")
        # Numbers as the scene files write them: no hexadecimal, no spaces; a range in words.
        for option in (["--kink", "0x10"], ["--entry", " 0x10"], ["--entry", "1e-320"],
                       ["--entry", "0"], ["--kink", "nan"]):
            result = grbd(0, "chute", out, *option)
            self.assertEqual(result.returncode, 2, (option, result.stderr))
            self.assertLess(len(result.stderr.splitlines()[0]), 160, result.stderr)

    def test_an_output_a_run_holds_is_in_use_not_damaged(self):
        out = self.path("o.h5")
        result = grbd(0, "run", self.scene, "-q", "-o", out, "-c", self.path("c.h5"),
                      "--end-time", "0.002")
        self.assertEqual(result.returncode, 0, result.stderr)
        with open(out, "rb") as held:
            fcntl.flock(held, fcntl.LOCK_EX)  # as a running grbd run holds its output
            for command in ("info", "chute"):
                result = grbd(0, command, out)
                self.assertEqual(result.returncode, 3, result.stderr)
                self.assertIn("is in use", result.stderr)
                self.assertNotIn("damaged", result.stderr)


if __name__ == "__main__":
    GRBD, MPIEXEC, CHUTE = sys.argv[1:4]
    unittest.main(argv=sys.argv[:1] + sys.argv[4:], verbosity=2)
