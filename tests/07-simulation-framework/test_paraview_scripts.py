#!/usr/bin/env python3
"""Chapter 7: the ParaView helper scripts refuse a missing input at once, without ParaView.

Run by CTest as `test_paraview_scripts.py`. paraview_spheres.py checks the XDMF file and the HDF5
file it names before it loads ParaView, and exits with 2 and one message; headless.py does not try
a command again that exited with 2. A stand-in for Xvfb (it reports display 99 on the file
descriptor it is given, then waits to be stopped) lets headless.py run here without an X server.
"""

import os
import subprocess
import sys
import tempfile
import textwrap
import unittest

FOLDER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "chapters",
                      "07-simulation-framework")
SPHERES = os.path.join(FOLDER, "paraview_spheres.py")
HEADLESS = os.path.join(FOLDER, "headless.py")

FAKE_XVFB = textwrap.dedent("""\
    #!/usr/bin/env python3
    import os, signal, sys, time
    fd = int(sys.argv[sys.argv.index("-displayfd") + 1])
    os.write(fd, b"99\\n")
    os.close(fd)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))
    time.sleep(60)
    """)


class Scripts(unittest.TestCase):
    def setUp(self):
        self._folder = tempfile.TemporaryDirectory(prefix="grbd_paraview_")
        self.dir = self._folder.name

    def tearDown(self):
        self._folder.cleanup()

    def spheres(self, *args):
        return subprocess.run([sys.executable, SPHERES, *args], capture_output=True, text=True,
                              timeout=60)

    def test_a_missing_run_is_one_message_and_exit_2(self):
        result = self.spheres(os.path.join(self.dir, "silo.xmf"), "out.png")
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("silo.xmf: no such file", result.stderr)
        self.assertNotIn("Traceback", result.stderr)
        xmf = os.path.join(self.dir, "run.xmf")
        with open(xmf, "w") as f:
            f.write('<DataItem Format="HDF">run.h5:/records/000000/I_r_S</DataItem>\n')
        result = self.spheres(xmf, "out.png")
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertIn("run.h5: no such file (the HDF5 output that", result.stderr)
        self.assertFalse(os.path.exists("out.png"))

    def test_headless_does_not_retry_a_command_that_refused_its_input(self):
        xvfb = os.path.join(self.dir, "Xvfb")
        with open(xvfb, "w") as f:
            f.write(FAKE_XVFB)
        os.chmod(xvfb, 0o755)
        missing = os.path.join(self.dir, "missing.xmf")
        result = subprocess.run([sys.executable, HEADLESS, xvfb, sys.executable, SPHERES, missing,
                                 "out.png"], capture_output=True, text=True, timeout=120)
        self.assertEqual(result.returncode, 2, result.stderr)
        self.assertEqual(result.stderr.count("no such file"), 1, result.stderr)
        self.assertNotIn("attempt", result.stderr)
        # A command that fails otherwise is tried three times.
        result = subprocess.run([sys.executable, HEADLESS, xvfb, sys.executable, "-c",
                                 "import sys; sys.exit(1)"], capture_output=True, text=True,
                                timeout=120)
        self.assertEqual(result.returncode, 1)
        self.assertIn("attempt 3 of 3", result.stderr)


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"] + sys.argv[1:])
