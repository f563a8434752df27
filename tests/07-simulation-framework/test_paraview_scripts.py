#!/usr/bin/env python3
"""Chapter 7: the ParaView helper scripts refuse a missing input at once, without ParaView, and
frame any run.

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


class Framing(unittest.TestCase):
    """paraview_spheres.frame() shows any run whole, beside the colour bar's strip: the image
    takes the data's shape, and every corner of the data's box projects into the data's part."""

    def corners_in_picture(self, bounds):
        sys.path.insert(0, FOLDER)
        import paraview_spheres as ps
        size, (position, focal, up, scale) = ps.frame(bounds)
        back = [p - f for p, f in zip(position, focal)]
        n = sum(b * b for b in back) ** 0.5
        back = [b / n for b in back]
        right = [up[1] * back[2] - up[2] * back[1], up[2] * back[0] - up[0] * back[2],
                 up[0] * back[1] - up[1] * back[0]]
        metres_per_pixel = 2.0 * scale / size[1]
        for x in bounds[0:2]:
            for y in bounds[2:4]:
                for z in bounds[4:6]:
                    d = [x - focal[0], y - focal[1], z - focal[2]]
                    px = size[0] / 2 + sum(a * b for a, b in zip(right, d)) / metres_per_pixel
                    py = size[1] / 2 + sum(a * b for a, b in zip(up, d)) / metres_per_pixel
                    self.assertGreaterEqual(px, 0.0)
                    self.assertLessEqual(px, size[0] - ps.BAR_STRIP)  # never under the bar
                    self.assertGreaterEqual(py, 0.0)
                    self.assertLessEqual(py, size[1])
        return size

    def test_a_silo_is_tall_and_a_chute_wide_and_both_whole(self):
        silo = self.corners_in_picture([-0.015, 0.015, -0.015, 0.015, 0.0, 0.26])
        self.assertGreater(silo[1], silo[0])
        chute = self.corners_in_picture([-0.1, 0.9, -0.1, 0.1, -0.05, 0.4])
        self.assertGreater(chute[0], chute[1])
        cube = self.corners_in_picture([5.0, 6.0, 5.0, 6.0, 5.0, 6.0])  # away from the origin
        self.assertGreater(cube[0], 0)
        flat = self.corners_in_picture([0.0, 1.0, 0.0, 1.0, 0.0, 0.0])  # a floor alone
        self.assertGreater(flat[0], flat[1])


if __name__ == "__main__":
    unittest.main(argv=[sys.argv[0], "-v"] + sys.argv[1:])
