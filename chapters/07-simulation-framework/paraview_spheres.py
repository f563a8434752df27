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


# The view: from the side (−y), a little from the front (+x) and from above (+z), as one looks
# at a silo or down a chute; an orthographic projection, so that the frame fits the data exactly.
VIEW_FROM = (0.35, -1.0, 0.45)
DATA_SIDE = 900  # pixels: the longer side of the data's part of the image
BAR_STRIP = 160  # pixels at the right for the colour bar


def frame(bounds):
    """Image size and camera (position, focal point, view up, parallel scale) that show the box
    `bounds` = [xmin, xmax, ymin, ymax, zmin, zmax] whole, seen from VIEW_FROM, with a strip at
    the right for the colour bar: the picture takes the shape of the data, tall for a silo and
    wide for a chute."""
    import math
    norm = math.sqrt(sum(c * c for c in VIEW_FROM))
    back = [c / norm for c in VIEW_FROM]  # from the focal point towards the camera
    up = [0.0, 0.0, 1.0]
    dot = sum(u * b for u, b in zip(up, back))
    up = [u - dot * b for u, b in zip(up, back)]
    n = math.sqrt(sum(u * u for u in up))
    up = [u / n for u in up]
    right = [up[1] * back[2] - up[2] * back[1], up[2] * back[0] - up[0] * back[2],
             up[0] * back[1] - up[1] * back[0]]
    corners = [(x, y, z) for x in bounds[0:2] for y in bounds[2:4] for z in bounds[4:6]]
    across = [sum(a * c for a, c in zip(right, p)) for p in corners]
    along = [sum(a * c for a, c in zip(up, p)) for p in corners]
    width = max(max(across) - min(across), 1e-12) * 1.06  # a margin of 3 % on each side
    height = max(max(along) - min(along), 1e-12) * 1.06
    # The data's part of the image takes their shape, kept between 1:3 and 3:1.
    aspect = min(max(width / height, 1.0 / 3.0), 3.0)
    if aspect >= 1.0:
        data = [DATA_SIDE, int(round(DATA_SIDE / aspect))]
    else:
        data = [int(round(DATA_SIDE * aspect)), DATA_SIDE]
    size = [data[0] + BAR_STRIP, data[1]]
    scale = max(height, width * data[1] / data[0]) / 2.0  # half the picture's height, in metres
    strip = BAR_STRIP * 2.0 * scale / data[1]  # the strip's width in metres
    centre = [(bounds[0] + bounds[1]) / 2, (bounds[2] + bounds[3]) / 2, (bounds[4] + bounds[5]) / 2]
    # The focal point moves right by half the strip, so that the data sit left of it.
    focal = [c + strip / 2.0 * r for c, r in zip(centre, right)]
    distance = 4.0 * max(width, height)
    position = [f + distance * b for f, b in zip(focal, back)]
    return size, (position, focal, up, scale)


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

    # The XDMF file holds a grid of the bodies per record (a temporal collection; with contacts,
    # each record is a spatial collection of the bodies' and the contacts' grids) and, where the
    # scene has static geometry, the grid "static" of its triangles.
    run = pv.XDMFReader(registrationName="run", FileNames=[xmf])
    run.UpdatePipelineInformation()
    grids = list(run.GetProperty("GridInfo")[::2]) if run.GetProperty("GridInfo") else []
    # The bodies only: not the static geometry, nor the contacts' lines of a run that writes them
    # ([output] contacts), whose grids are named contacts, contacts[1], ...
    run.GridStatus = [g for g in grids if g != "static" and not g.startswith("contacts")]
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
    statics = None
    if "static" in grids:
        statics = pv.XDMFReader(registrationName="static", FileNames=[xmf])
        statics.GridStatus = ["static"]

    view = pv.CreateView("RenderView")
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
    bounds = list(spheres.GetDataInformation().GetBounds())
    if statics is not None:
        # The walls, floors and meshes, light grey; their faces point into the free space, so
        # culling the faces turned away from the camera lets it look through the near walls.
        walls = pv.Show(statics, view)
        pv.ColorBy(walls, None)
        walls.AmbientColor = walls.DiffuseColor = [0.8, 0.8, 0.8]
        walls.BackfaceRepresentation = "Cull Backface"
        b = statics.GetDataInformation().GetBounds()
        bounds = [min(bounds[0], b[0]), max(bounds[1], b[1]), min(bounds[2], b[2]),
                  max(bounds[3], b[3]), min(bounds[4], b[4]), max(bounds[5], b[5])]
    size, camera = frame(bounds)
    view.ViewSize = size
    view.CameraParallelProjection = 1
    view.CameraPosition, view.CameraFocalPoint, view.CameraViewUp, view.CameraParallelScale = camera
    # The colour bar in a strip of its own at the right, beside the data, never over it.
    bar.WindowLocation = "Any Location"
    bar.Orientation = "Vertical"
    bar.Position = [1.0 - (BAR_STRIP - 20.0) / size[0], 0.15]
    bar.ScalarBarLength = 0.7
    bar.AutomaticLabelFormat = 0
    bar.LabelFormat = bar.RangeLabelFormat = "%-#.2g"
    pv.SaveScreenshot(image, view, ImageResolution=size)
    print("paraview_spheres.py: %s: record %d of %d (t = %g s) -> %s"
          % (xmf, record, len(times), times[record], image))
    # Release the render window before the interpreter ends: left to ParaView's own teardown, its
    # GLX context fails under Xvfb (GLXBadContext) after the image is written, and the exit code
    # says failure.
    pv.Delete(view)
    pv.Delete(spheres)
    pv.Delete(run)
    if statics is not None:
        pv.Delete(statics)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
