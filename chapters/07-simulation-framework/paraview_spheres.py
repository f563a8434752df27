"""Render the bodies of a grbd run as spheres with ParaView (chapter 7), without a window.

Usage:
    headless.py Xvfb pvbatch paraview_spheres.py RUN.xmf IMAGE.png [RECORD]
    (or, on a machine with a display: pvbatch paraview_spheres.py RUN.xmf IMAGE.png [RECORD])

Opens the XDMF description beside a grbd output file, draws every body as a sphere of its own
radius (the Glyph filter, scaled by the record's `radius`), colours the spheres by the magnitude
of their velocity, and saves the last record (or record number RECORD, from 0) as a PNG image
seen from the side, a little from above. These are the steps the chapter describes for the
ParaView window. ParaView is not a dependency of grbd: Debian 12 packages it as `paraview` and
`python3-paraview` (pvbatch); its build renders through GLX, hence a virtual X server (Xvfb,
started by headless.py beside this script) and Mesa's software renderer (libgl1-mesa-dri) on a
machine without a display.
"""

import os
import re
import sys


def missing_input(xmf):
    """What is wrong with the run to draw, or None: the XDMF file and the HDF5 file it names must
    be readable (else ParaView prints a reader error per dataset and a traceback)."""
    if not os.path.isfile(xmf):
        return f"{xmf}: no such file (the XDMF file beside a grbd output, e.g. build/runs/silo.xmf)"
    try:
        with open(xmf, encoding="utf-8") as f:
            text = f.read()
    except (OSError, UnicodeDecodeError) as error:
        return f"{xmf}: cannot read it: {error}"
    m = re.search(r'Format="HDF">([^:<]+):', text)
    if m is None:
        return f"{xmf}: not the XDMF file of a grbd output (no HDF data item)"
    h5 = os.path.join(os.path.dirname(xmf), m.group(1))
    if not os.path.isfile(h5):
        return f"{h5}: no such file (the HDF5 output that {xmf} describes)"
    return None


def main(argv):
    if len(argv) not in (3, 4):
        sys.stderr.write(__doc__)
        return 2
    xmf, image = argv[1], argv[2]
    # Checked before ParaView is loaded: a missing input is one message and exit code 2, which
    # headless.py does not retry.
    problem = missing_input(xmf)
    if problem:
        sys.stderr.write(f"paraview_spheres.py: {problem}\n")
        return 2
    from paraview import simple as pv  # noqa: E402 (only once the input is known to be there)

    run = pv.XDMFReader(registrationName="run", FileNames=[xmf])
    run.UpdatePipelineInformation()
    times = list(run.TimestepValues) if run.TimestepValues else [0.0]
    record = int(argv[3]) if len(argv) == 4 else len(times) - 1
    if not 0 <= record < len(times):
        sys.stderr.write("paraview_spheres.py: record %d: expected 0 to %d\n" % (record, len(times) - 1))
        return 2
    spheres = pv.Glyph(registrationName="spheres", Input=run, GlyphType="Sphere")
    spheres.OrientationArray = ["POINTS", "No orientation array"]
    spheres.ScaleArray = ["POINTS", "radius"]
    spheres.ScaleFactor = 2.0  # the sphere glyph has radius 0.5
    spheres.GlyphMode = "All Points"
    spheres.GlyphType.ThetaResolution = 16
    spheres.GlyphType.PhiResolution = 12

    view = pv.CreateView("RenderView")
    view.ViewSize = [640, 900]
    view.ViewTime = times[record]
    view.OrientationAxesVisibility = 0
    view.Background = [1.0, 1.0, 1.0]
    try:  # ParaView 5.10 and later keep the background in a palette unless told otherwise
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    display = pv.Show(spheres, view)
    pv.ColorBy(display, ("POINTS", "velocity", "Magnitude"))
    display.RescaleTransferFunctionToDataRange(True, False)
    display.SetScalarBarVisibility(view, True)
    bar = pv.GetScalarBar(pv.GetColorTransferFunction("velocity"), view)
    bar.Title = "speed [m/s]"
    bar.ComponentTitle = ""
    bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
    view.CameraPosition = [0.35, -1.0, 0.45]  # from the side, a little from above
    view.CameraFocalPoint = [0.0, 0.0, 0.0]
    view.CameraViewUp = [0.0, 0.0, 1.0]
    view.ResetCamera()
    view.GetActiveCamera().Dolly(1.35)  # fill the picture with the silo
    pv.SaveScreenshot(image, view, ImageResolution=[640, 900])
    print("paraview_spheres.py: %s: record %d of %d (t = %g s) -> %s"
          % (xmf, record, len(times), times[record], image))
    # Release the render window before the interpreter ends: left to ParaView's own teardown, its
    # GLX context fails under Xvfb (GLXBadContext) after the image is written, and the exit code
    # says failure.
    pv.Delete(view)
    pv.Delete(spheres)
    pv.Delete(run)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
