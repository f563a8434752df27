"""A small SVG drawing kit for the explanatory figures of the book (Python 3, standard library only).

It writes SVG 1.1 text directly: no external resources, no fonts to embed, and the same bytes on
every run (coordinates are written with a fixed number of decimals, elements in the order they
were drawn). A figure script builds one Canvas, draws on it in pixel coordinates (x to the right,
y downwards, as in SVG) or through a Camera that projects points (x, y, z) of 3-D space, and saves
it:

    canvas = Canvas(640, 480)
    cam = Camera(azimuth=30, elevation=20, scale=80, origin=(320, 300))
    canvas.arrow(cam.project((0, 0, 0)), cam.project((1, 0, 0)), color=BLACK)
    canvas.text(cam.project((1.1, 0, 0)), "*{e}_{x}^{I}")
    canvas.save(path)

Labels use a tiny markup, no LaTeX:  _{...} a subscript, ^{...} a superscript (directly after a
subscript the two are stacked), *{...} bold (vectors), ~{...} italic (scalars); the groups nest,
and a leading _{I} gives the left frame subscript of the book's notation, "_{I}*{r}_{S}".
"""

from __future__ import annotations

import math
import os
import sys
from typing import Iterable, Sequence

# A colour-blind safe palette (Okabe–Ito) and the greys of the figures.
BLACK = "#000000"
GREY = "#6b6b6b"
LIGHT_GREY = "#b8b8b8"
BLUE = "#0072b2"
ORANGE = "#e69f00"
VERMILION = "#d55e00"
GREEN = "#009e73"
SKY = "#56b4e9"
PURPLE = "#cc79a7"
YELLOW = "#f0e442"

FONT_FAMILY = "DejaVu Sans, Helvetica, Arial, sans-serif"
FONT_SIZE = 16


def fmt(value: float, digits: int = 2) -> str:
    """A number with at most `digits` decimals, no trailing zeros, never "-0"."""
    text = f"{value:.{digits}f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    if text in ("-0", ""):
        text = "0"
    return text


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;")


def fail(message: str) -> None:
    """Prints `message` to stderr and exits with status 2 (a usage error)."""
    print(message, file=sys.stderr)
    raise SystemExit(2)


def output_path(argv: Sequence[str], script: str) -> str:
    """The single command-line argument OUTPUT.svg of a figure script, or exit 2 with a usage line."""
    usage = f"usage: python3 {script} OUTPUT.svg"
    if len(argv) != 2:
        fail(f"{script}: expected exactly one argument, the output file; found {len(argv) - 1}\n{usage}")
    path = argv[1]
    if not path.endswith(".svg"):
        fail(f"{script}: expected an output file ending in .svg, found '{path}'\n{usage}")
    return path


# --------------------------------------------------------------------------------------------
# Small vector algebra on tuples
# --------------------------------------------------------------------------------------------

def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def scale(s, a):
    return tuple(s * x for x in a)


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    return math.sqrt(dot(a, a))


def unit(a):
    n = norm(a)
    return tuple(x / n for x in a)


def lerp(a, b, t):
    return tuple(x + t * (y - x) for x, y in zip(a, b))


def matvec(m, v):
    return tuple(dot(row, v) for row in m)


def column(m, j):
    return tuple(row[j] for row in m)


def rotation_from_quaternion(p):
    """R(p) = (p0² − p_rᵀp_r) I + 2 p_r p_rᵀ + 2 p0 p̃_r for a unit quaternion p = (p0, p1, p2, p3)
    (scalar first), as a tuple of three rows: the rotation A_IK of chapter 1."""
    p0, p1, p2, p3 = p
    pr = (p1, p2, p3)
    s = p0 * p0 - dot(pr, pr)
    skew = ((0.0, -p3, p2), (p3, 0.0, -p1), (-p2, p1, 0.0))
    return tuple(
        tuple((s if i == j else 0.0) + 2.0 * pr[i] * pr[j] + 2.0 * p0 * skew[i][j] for j in range(3))
        for i in range(3)
    )


def convex_hull(points):
    """The convex hull of 2-D points, counter-clockwise in a y-up frame (Andrew's monotone chain)."""
    pts = sorted(set((round(x, 6), round(y, 6)) for x, y in points))
    if len(pts) < 3:
        return pts

    def turn(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for p in pts:
        while len(lower) >= 2 and turn(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and turn(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return lower[:-1] + upper[:-1]


# --------------------------------------------------------------------------------------------
# The camera
# --------------------------------------------------------------------------------------------

class Camera:
    """Projects points (x, y, z) of a right-handed 3-D frame with z up onto the canvas.

    orthographic: the viewer looks from the direction of azimuth `azimuth` (degrees from +x
    towards +y) and elevation `elevation` (degrees above the xy-plane); lengths are multiplied by
    `scale` (px per unit) and the point (0, 0, 0) lands on the pixel `origin`.
    oblique (cabinet): y to the right, z up, and x drawn receding at the angle `azimuth` below the
    horizontal to the left, shortened by `depth_ratio`.
    """

    def __init__(self, azimuth=30.0, elevation=20.0, scale=100.0, origin=(320.0, 240.0),
                 projection="orthographic", depth_ratio=0.5):
        if projection not in ("orthographic", "oblique"):
            raise ValueError(f"Camera: projection must be 'orthographic' or 'oblique', found {projection!r}")
        self.projection = projection
        self.scale = scale
        self.origin = origin
        phi = math.radians(azimuth)
        theta = math.radians(elevation)
        if projection == "orthographic":
            # toward the viewer, screen right and screen up: an orthonormal right-handed triple
            self.view = (math.cos(theta) * math.cos(phi), math.cos(theta) * math.sin(phi), math.sin(theta))
            self.right = (-math.sin(phi), math.cos(phi), 0.0)
            self.up = (-math.sin(theta) * math.cos(phi), -math.sin(theta) * math.sin(phi), math.cos(theta))
        else:
            k = depth_ratio
            self.right = (-k * math.cos(phi), 1.0, 0.0)
            self.up = (-k * math.sin(phi), 0.0, 1.0)
            self.view = unit((1.0, k * math.cos(phi), k * math.sin(phi)))

    def project(self, p):
        """The pixel (x, y) of the point p."""
        return (self.origin[0] + self.scale * dot(self.right, p),
                self.origin[1] - self.scale * dot(self.up, p))

    def depth(self, p):
        """The distance of p towards the viewer (larger is nearer)."""
        return dot(self.view, p)

    def project_all(self, points):
        return [self.project(p) for p in points]


def circle3d(centre, axis_u, axis_v, radius, n=144, start=0.0, stop=2.0 * math.pi):
    """Points of the circle (or arc) centre + radius (cos t u + sin t v), t from start to stop."""
    pts = []
    for k in range(n + 1):
        t = start + (stop - start) * k / n
        pts.append(add(centre, add(scale(radius * math.cos(t), axis_u), scale(radius * math.sin(t), axis_v))))
    return pts


# --------------------------------------------------------------------------------------------
# Labels: the markup  _{sub}  ^{sup}  *{bold}  ~{italic}
# --------------------------------------------------------------------------------------------

def _parse(markup: str, i: int = 0, closing: bool = False):
    """Parses markup from index i into a list of (kind, content) items, kind in
    'text', '_', '^', '*', '~'; content is a string for 'text' and a list otherwise."""
    items = []
    buf = []
    while i < len(markup):
        c = markup[i]
        if c in "_^*~" and i + 1 < len(markup) and markup[i + 1] == "{":
            if buf:
                items.append(("text", "".join(buf)))
                buf = []
            inner, i = _parse(markup, i + 2, True)
            items.append((c, inner))
            continue
        if c == "}" and closing:
            if buf:
                items.append(("text", "".join(buf)))
            return items, i + 1
        buf.append(c)
        i += 1
    if closing:
        raise ValueError(f"label markup: unbalanced braces in {markup!r}")
    if buf:
        items.append(("text", "".join(buf)))
    return items, i


def _plain_length(items) -> float:
    """An estimate of the width of items in em (for stacking a superscript over a subscript)."""
    width = 0.0
    for kind, content in items:
        if kind == "text":
            width += 0.6 * len(content)
        else:
            w = _plain_length(content)
            width += 0.7 * w if kind in "_^" else w
    return width


def _render(items, size: float) -> str:
    out = []
    previous = None
    for kind, content in items:
        if kind == "text":
            out.append(_escape(content))
        elif kind == "_":
            out.append(f'<tspan baseline-shift="sub" font-size="70%">{_render(content, size * 0.7)}</tspan>')
        elif kind == "^":
            dx = ""
            if previous is not None and previous[0] == "_":
                dx = f' dx="{fmt(-_plain_length(previous[1]) * 0.7 * size)}"'
            out.append(f'<tspan baseline-shift="super" font-size="70%"{dx}>{_render(content, size * 0.7)}</tspan>')
        elif kind == "*":
            out.append(f'<tspan font-weight="bold">{_render(content, size)}</tspan>')
        elif kind == "~":
            out.append(f'<tspan font-style="italic">{_render(content, size)}</tspan>')
        previous = (kind, content)
    return "".join(out)


def label_markup(markup: str, size: float = FONT_SIZE) -> str:
    """The SVG content (text and tspans) of a label in the markup of this module."""
    items, _ = _parse(markup)
    return _render(items, size)


# --------------------------------------------------------------------------------------------
# The canvas
# --------------------------------------------------------------------------------------------

def _points_attr(points) -> str:
    return " ".join(f"{fmt(x)},{fmt(y)}" for x, y in points)


def _style(stroke=None, width=None, fill=None, dash=None, opacity=None, fill_opacity=None,
           stroke_opacity=None, cap=None, join=None) -> str:
    attrs = []
    if fill is not None:
        attrs.append(f'fill="{fill}"')
    if fill_opacity is not None and fill_opacity != 1.0:
        attrs.append(f'fill-opacity="{fmt(fill_opacity, 3)}"')
    if stroke is not None:
        attrs.append(f'stroke="{stroke}"')
    if width is not None and stroke not in (None, "none"):
        attrs.append(f'stroke-width="{fmt(width)}"')
    if stroke_opacity is not None and stroke_opacity != 1.0:
        attrs.append(f'stroke-opacity="{fmt(stroke_opacity, 3)}"')
    if dash and stroke not in (None, "none"):
        attrs.append(f'stroke-dasharray="{" ".join(fmt(d) for d in dash)}"')
    if opacity is not None and opacity != 1.0:
        attrs.append(f'opacity="{fmt(opacity, 3)}"')
    if cap is not None and stroke not in (None, "none"):
        attrs.append(f'stroke-linecap="{cap}"')
    if join is not None and stroke not in (None, "none"):
        attrs.append(f'stroke-linejoin="{join}"')
    return " ".join(attrs)


class Canvas:
    """An SVG document of width × height px (viewBox 0 0 width height) with a white background."""

    def __init__(self, width: int = 640, height: int = 480, background: str | None = "#ffffff",
                 title: str | None = None, font_size: float = FONT_SIZE):
        self.width = width
        self.height = height
        self.font_size = font_size
        self._defs: list[str] = []
        self._def_ids: set[str] = set()
        self._body: list[str] = []
        self._title = title
        if background:
            self._body.append(f'<rect x="0" y="0" width="{width}" height="{height}" fill="{background}"/>')

    # -- definitions ---------------------------------------------------------------------------

    def _marker(self, color: str, length: float, half_width: float) -> str:
        """The id of an arrowhead marker in `color`, `length` px long, defined once."""
        ident = f"arrow-{color.lstrip('#')}-{fmt(length, 1).replace('.', 'p')}-{fmt(half_width, 1).replace('.', 'p')}"
        if ident not in self._def_ids:
            self._def_ids.add(ident)
            # Tip at (length, 0); the marker sits on the end of the shortened line (refX, 0).
            ref = length * 0.45
            w = half_width
            self._defs.append(
                f'<marker id="{ident}" markerUnits="userSpaceOnUse" orient="auto" overflow="visible" '
                f'markerWidth="{fmt(length)}" markerHeight="{fmt(2 * w)}" '
                f'viewBox="0 {fmt(-w)} {fmt(length)} {fmt(2 * w)}" refX="{fmt(ref)}" refY="0">'
                f'<path d="M 0,{fmt(-w)} L {fmt(length)},0 L 0,{fmt(w)} L {fmt(length * 0.18)},0 Z" '
                f'fill="{color}" stroke="none"/></marker>')
        return ident

    def radial_gradient(self, ident: str, stops: Sequence[tuple[float, str, float]],
                        cx: float = 0.35, cy: float = 0.32, r: float = 0.75) -> str:
        """Defines a radial gradient (stops: offset, colour, opacity) once; returns "url(#ident)"."""
        if ident not in self._def_ids:
            self._def_ids.add(ident)
            parts = [f'<radialGradient id="{ident}" cx="{fmt(cx, 3)}" cy="{fmt(cy, 3)}" r="{fmt(r, 3)}" '
                     f'fx="{fmt(cx, 3)}" fy="{fmt(cy, 3)}">']
            for offset, color, opacity in stops:
                parts.append(f'<stop offset="{fmt(offset, 3)}" stop-color="{color}" stop-opacity="{fmt(opacity, 3)}"/>')
            parts.append("</radialGradient>")
            self._defs.append("".join(parts))
        return f"url(#{ident})"

    def hatch_pattern(self, ident: str, color: str, spacing: float = 7.0, width: float = 1.0,
                      angle: float = 45.0) -> str:
        """Defines a pattern of parallel lines once; returns "url(#ident)"."""
        if ident not in self._def_ids:
            self._def_ids.add(ident)
            self._defs.append(
                f'<pattern id="{ident}" patternUnits="userSpaceOnUse" width="{fmt(spacing)}" '
                f'height="{fmt(spacing)}" patternTransform="rotate({fmt(angle)})">'
                f'<line x1="0" y1="0" x2="0" y2="{fmt(spacing)}" stroke="{color}" stroke-width="{fmt(width)}"/>'
                f'</pattern>')
        return f"url(#{ident})"

    # -- primitives ----------------------------------------------------------------------------

    def comment(self, text: str) -> None:
        self._body.append(f"<!-- {text.replace('--', '–')} -->")

    def line(self, p, q, stroke=BLACK, width=1.2, dash=None, opacity=1.0, cap="round") -> None:
        self._body.append(
            f'<line x1="{fmt(p[0])}" y1="{fmt(p[1])}" x2="{fmt(q[0])}" y2="{fmt(q[1])}" '
            + _style(stroke=stroke, width=width, dash=dash, opacity=opacity, cap=cap) + "/>")

    def polyline(self, points, stroke=BLACK, width=1.2, dash=None, opacity=1.0, cap="round",
                 join="round") -> None:
        self._body.append(f'<polyline points="{_points_attr(points)}" '
                          + _style(stroke=stroke, width=width, fill="none", dash=dash, opacity=opacity,
                                   cap=cap, join=join) + "/>")

    def polygon(self, points, fill="none", fill_opacity=1.0, stroke="none", width=1.0, dash=None,
                opacity=1.0, join="round") -> None:
        self._body.append(f'<polygon points="{_points_attr(points)}" '
                          + _style(stroke=stroke, width=width, fill=fill, dash=dash, opacity=opacity,
                                   fill_opacity=fill_opacity, join=join) + "/>")

    def rect(self, x, y, w, h, fill="none", fill_opacity=1.0, stroke="none", width=1.0, dash=None,
             opacity=1.0) -> None:
        self._body.append(f'<rect x="{fmt(x)}" y="{fmt(y)}" width="{fmt(w)}" height="{fmt(h)}" '
                          + _style(stroke=stroke, width=width, fill=fill, dash=dash, opacity=opacity,
                                   fill_opacity=fill_opacity) + "/>")

    def circle(self, c, r, fill="none", fill_opacity=1.0, stroke=BLACK, width=1.2, dash=None,
               opacity=1.0) -> None:
        self._body.append(f'<circle cx="{fmt(c[0])}" cy="{fmt(c[1])}" r="{fmt(r)}" '
                          + _style(stroke=stroke, width=width, fill=fill, dash=dash, opacity=opacity,
                                   fill_opacity=fill_opacity) + "/>")

    def ellipse(self, c, rx, ry, angle=0.0, fill="none", fill_opacity=1.0, stroke=BLACK, width=1.2,
                dash=None, opacity=1.0) -> None:
        """An ellipse with semi-axes rx, ry, the rx axis turned by `angle` degrees (clockwise on
        screen, as SVG's rotate)."""
        transform = f' transform="rotate({fmt(angle, 3)} {fmt(c[0])} {fmt(c[1])})"' if angle else ""
        self._body.append(f'<ellipse cx="{fmt(c[0])}" cy="{fmt(c[1])}" rx="{fmt(rx)}" ry="{fmt(ry)}"{transform} '
                          + _style(stroke=stroke, width=width, fill=fill, dash=dash, opacity=opacity,
                                   fill_opacity=fill_opacity) + "/>")

    def dot(self, c, r=3.2, color=BLACK, stroke="#ffffff", width=1.0) -> None:
        """A filled point marker."""
        self.circle(c, r, fill=color, stroke=stroke, width=width)

    def arrow(self, p, q, color=BLACK, width=1.6, head=None, dash=None, opacity=1.0) -> None:
        """An arrow from p to q (pixels) whose tip is exactly at q; the line stops inside the head,
        so that a thick or dashed line never pokes through the tip."""
        length = head if head is not None else 7.0 + 3.0 * width
        half = length * 0.36
        d = math.hypot(q[0] - p[0], q[1] - p[1])
        if d < 1e-9:
            return
        ident = self._marker(color, length, half)
        back = length * 0.55  # tip − back is where the line ends (inside the head)
        if d <= back:
            back = 0.5 * d
        e = (q[0] - (q[0] - p[0]) * back / d, q[1] - (q[1] - p[1]) * back / d)
        self._body.append(
            f'<line x1="{fmt(p[0])}" y1="{fmt(p[1])}" x2="{fmt(e[0])}" y2="{fmt(e[1])}" '
            + _style(stroke=color, width=width, dash=dash, opacity=opacity, cap="butt")
            + f' marker-end="url(#{ident})"/>')

    def path(self, d: str, stroke=BLACK, width=1.2, fill="none", fill_opacity=1.0, dash=None,
             opacity=1.0) -> None:
        """A raw path (d is written as given: build it with fmt for deterministic output)."""
        self._body.append(f'<path d="{d}" ' + _style(stroke=stroke, width=width, fill=fill, dash=dash,
                                                      opacity=opacity, fill_opacity=fill_opacity,
                                                      cap="round", join="round") + "/>")

    def text(self, pos, markup: str, size: float | None = None, anchor: str = "middle",
             color: str = BLACK, valign: str = "middle", halo: bool = True, weight: str | None = None,
             italic: bool = False) -> None:
        """A label at the pixel pos: anchor start|middle|end horizontally, valign baseline|middle
        vertically (middle puts the centre of the lowercase letters on pos). halo draws a white
        outline under the glyphs, so that a label stays readable where it crosses a line."""
        if anchor not in ("start", "middle", "end"):
            raise ValueError(f"text: anchor must be start, middle or end, found {anchor!r}")
        size = size or self.font_size
        y = pos[1] + (0.36 * size if valign == "middle" else 0.0)
        extra = ""
        if weight:
            extra += f' font-weight="{weight}"'
        if italic:
            extra += ' font-style="italic"'
        if halo:
            extra += (' stroke="#ffffff" stroke-width="3.5" stroke-linejoin="round" '
                      'stroke-opacity="0.9" paint-order="stroke"')
        self._body.append(
            f'<text x="{fmt(pos[0])}" y="{fmt(y)}" font-size="{fmt(size)}" text-anchor="{anchor}" '
            f'fill="{color}"{extra}>{label_markup(markup, size)}</text>')

    # -- output --------------------------------------------------------------------------------

    def to_string(self) -> str:
        head = (f'<?xml version="1.0" encoding="UTF-8"?>\n'
                f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{self.width}" '
                f'height="{self.height}" viewBox="0 0 {self.width} {self.height}" '
                f'font-family="{FONT_FAMILY}" font-size="{fmt(self.font_size)}">\n')
        parts = [head]
        if self._title:
            parts.append(f"<title>{_escape(self._title)}</title>\n")
        if self._defs:
            parts.append("<defs>\n" + "\n".join(self._defs) + "\n</defs>\n")
        parts.append("\n".join(self._body))
        parts.append("\n</svg>\n")
        return "".join(parts)

    def save(self, path: str) -> None:
        """Writes the document to path (UTF-8, LF line ends); exits 1 with a message if it cannot."""
        try:
            with open(path, "w", encoding="utf-8", newline="\n") as f:
                f.write(self.to_string())
        except OSError as error:
            script = os.path.basename(sys.argv[0]) if sys.argv and sys.argv[0] else "svgdraw"
            print(f"{script}: cannot write {path}: {error.strerror}", file=sys.stderr)
            raise SystemExit(1)
