"""Figure ch05_coulomb_cone (chapter 5): the Coulomb cone K_μ = {λ : ‖λ_T‖ ≤ μ λ_N} and the prox
(the Euclidean projection) of three points onto it.

The projections are computed with the formula of grbd::contact::prox_cone (solutions/
05-contact-laws/prox.cpp, Exercise 5.3): a point of the cone is its own projection; a point of the
polar cone {μ ‖x_T‖ ≤ −x_N} projects to the apex 0; any other point projects along the normal of
the cone's surface onto y_N = (x_N + μ ‖x_T‖)/(1 + μ²), y_T = μ y_N x_T/‖x_T‖. The axis λ_N points
up, (λ_T1, λ_T2) span the horizontal plane, normal first as in the library.

Usage: python3 draw_coulomb_cone.py OUTPUT.svg   (writes that file only)
"""

import math
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common", "drawing"))

import svgdraw as sd  # noqa: E402

MU = 0.5
HEIGHT = 2.3          # the cone is drawn up to λ_N = HEIGHT
POLAR_DEPTH = 0.62    # the polar cone down to λ_N = −POLAR_DEPTH

cam = sd.Camera(azimuth=24.0, elevation=17.0, scale=104.0, origin=(300.0, 330.0))


def prox_cone(x, mu):
    """grbd::contact::prox_cone: x = (x_N, x_T1, x_T2) projected onto K_μ."""
    x_N = x[0]
    norm_T = math.sqrt(x[1] * x[1] + x[2] * x[2])
    if norm_T <= mu * x_N and x_N >= 0.0:
        return x
    if mu * norm_T <= -x_N:
        return (0.0, 0.0, 0.0)
    y_N = (x_N + mu * norm_T) / (1.0 + mu * mu)
    s = mu * y_N / norm_T
    return (y_N, s * x[1], s * x[2])


def world(lam):
    """(λ_N, λ_T1, λ_T2) → drawing coordinates (x, y, z) = (λ_T1, λ_T2, λ_N), λ_N up."""
    return (lam[1], lam[2], lam[0])


def P(lam):
    return cam.project(world(lam))


def ring(height, radius, n=144):
    """The horizontal circle ‖λ_T‖ = radius at λ_N = height, as (λ_N, λ_T1, λ_T2) points."""
    return [(height, radius * math.cos(2 * math.pi * k / n), radius * math.sin(2 * math.pi * k / n))
            for k in range(n + 1)]


def split_ring(points):
    """The circle's points split into the arcs in front of and behind the axis (by depth)."""
    front, back = [[]], [[]]
    prev = None
    for lam in points:
        is_front = cam.depth((lam[1], lam[2], 0.0)) >= 0.0
        if prev is not None and is_front != prev:
            (front if prev else back)[-1].append(P(lam))
            (front if is_front else back).append([])
        (front if is_front else back)[-1].append(P(lam))
        prev = is_front
    return [a for a in front if len(a) > 1], [a for a in back if len(a) > 1]


def main() -> None:
    path = sd.output_path(sys.argv, "draw_coulomb_cone.py")
    # In the tangential plane, the screen's right direction and the direction towards the viewer.
    d_right = (cam.right[0], cam.right[1])
    d_view = sd.unit((cam.view[0], cam.view[1]))

    def T(a, b):
        """a tangential vector a·right + b·towards the viewer, as (λ_T1, λ_T2)."""
        return (a * d_right[0] + b * d_view[0], a * d_right[1] + b * d_view[1])

    # The three points: outside (in the plane of λ_N and the screen's right), inside, polar.
    t = T(1.55, 0.0)
    x_out = (0.95, t[0], t[1])
    t = T(-0.35, 0.45)
    x_in = (1.55, t[0], t[1])
    t = T(0.4, 0.6)
    x_pol = (-0.55, t[0], t[1])
    y_out, y_in, y_pol = (prox_cone(x, MU) for x in (x_out, x_in, x_pol))
    assert y_in == x_in and y_pol == (0.0, 0.0, 0.0) and y_out != x_out

    c = sd.Canvas(640, 480, title="The Coulomb cone and the prox of three points onto it")
    apex = P((0.0, 0.0, 0.0))
    cone_col, polar_col = "#7fb8dc", "#b9b9b9"

    # The polar cone, below the apex.
    c.comment("polar cone")
    rim = ring(-POLAR_DEPTH, POLAR_DEPTH / MU)
    c.polygon(sd.convex_hull([apex] + [P(p) for p in rim]), fill=polar_col, fill_opacity=0.22)
    front, back = split_ring(rim)
    for arc in back:
        c.polyline(arc, stroke=sd.GREY, width=0.9, dash=(4, 3))
    for arc in front:
        c.polyline(arc, stroke=sd.GREY, width=0.9)

    # Axes through the apex.
    c.comment("axes")
    c.line(P((-0.85, 0.0, 0.0)), apex, stroke=sd.BLACK, width=1.1, dash=(4, 3))
    c.arrow(apex, P((HEIGHT + 0.8, 0.0, 0.0)), width=1.2)
    c.arrow(P((0.0, -1.0, 0.0)), P((0.0, 1.75, 0.0)), width=1.2)
    c.arrow(P((0.0, 0.0, -1.0)), P((0.0, 0.0, 1.75)), width=1.2)

    # The cone: translucent surface, generators, the top circle.
    c.comment("the Coulomb cone")
    top = ring(HEIGHT, MU * HEIGHT)
    hull = sd.convex_hull([apex] + [P(p) for p in top])
    c.polygon(hull, fill=cone_col, fill_opacity=0.28)
    for k in range(12):
        phi = 2.0 * math.pi * k / 12
        end = (HEIGHT, MU * HEIGHT * math.cos(phi), MU * HEIGHT * math.sin(phi))
        is_front = cam.depth((end[1], end[2], 0.0)) >= 0.0
        c.line(apex, P(end), stroke="#3d7ea6", width=0.8, opacity=0.9 if is_front else 0.45)
    c.polygon([P(p) for p in top], fill=cone_col, fill_opacity=0.18, stroke="#2f6f99", width=1.4)
    # The silhouette generators.
    for a, b in zip(hull, hull[1:] + hull[:1]):
        if (round(a[0], 6), round(a[1], 6)) == (round(apex[0], 6), round(apex[1], 6)) or \
           (round(b[0], 6), round(b[1], 6)) == (round(apex[0], 6), round(apex[1], 6)):
            c.line(a, b, stroke="#2f6f99", width=1.4)

    # The half-opening angle atan μ, between the axis and the generator through prox(x_out).
    g = sd.unit((1.0, y_out[1] / y_out[0], y_out[2] / y_out[0]))
    arc = [P(sd.scale(0.72, (math.cos(s), math.sin(s) * g[1] / math.hypot(g[1], g[2]),
                             math.sin(s) * g[2] / math.hypot(g[1], g[2]))))
           for s in [math.atan(MU) * k / 24 for k in range(25)]]
    c.polyline(arc, stroke=sd.BLACK, width=1.0)

    # The projections.
    c.comment("the three points and their projections")
    # outside → the lateral surface, along its normal; the generator through the foot
    gen_end = sd.scale(HEIGHT / y_out[0], y_out)
    c.line(apex, P(gen_end), stroke="#1f5f8b", width=2.0)
    c.arrow(P(x_out), P(y_out), color=sd.VERMILION, width=1.8, dash=(6, 4))
    # the right angle at the foot
    n_dir = sd.unit(sd.sub(x_out, y_out))
    s = 0.15
    corner = [sd.add(y_out, sd.scale(s, g)), sd.add(y_out, sd.add(sd.scale(s, g), sd.scale(s, n_dir))),
              sd.add(y_out, sd.scale(s, n_dir))]
    c.polyline([P(p) for p in corner], stroke=sd.BLACK, width=1.0)
    # polar → the apex
    c.arrow(P(x_pol), apex, color=sd.PURPLE, width=1.8, dash=(6, 4))
    # inside: a level circle of the cone through the point, and its radius, to place it in depth
    lvl = ring(x_in[0], MU * x_in[0])
    c.polyline([P(p) for p in lvl], stroke=sd.GREEN, width=0.9, dash=(3, 3))
    c.line(P((x_in[0], 0.0, 0.0)), P(x_in), stroke=sd.GREEN, width=1.0)
    for x, col in ((x_out, sd.VERMILION), (y_out, sd.VERMILION), (x_pol, sd.PURPLE), (x_in, sd.GREEN)):
        c.dot(P(x), r=4.0, color=col)
    c.dot(apex, r=3.4)

    # Labels.
    q = P((HEIGHT + 0.8, 0.0, 0.0))
    c.text((q[0] + 10, q[1] + 4), "~{λ}_{N}", anchor="start")
    q = P((0.0, 1.75, 0.0))
    c.text((q[0] + 6, q[1] + 16), "~{λ}_{T1}", anchor="start")
    q = P((0.0, 0.0, 1.75))
    c.text((q[0] + 10, q[1] + 2), "~{λ}_{T2}", anchor="start")
    q = max(P(p) for p in top)  # the rightmost point of the top circle
    c.text((q[0] + 12, q[1] - 6), "~{K}_{μ}", size=18, color="#1f5f8b", anchor="start")
    c.text((apex[0] + 92, apex[1] + 60), "~{K}_{μ}°", size=17, color=sd.GREY, anchor="middle")
    q = P(sd.scale(0.72, (math.cos(0.5 * math.atan(MU)), math.sin(0.5 * math.atan(MU)) * g[1] / math.hypot(g[1], g[2]),
                         math.sin(0.5 * math.atan(MU)) * g[2] / math.hypot(g[1], g[2]))))
    c.text((q[0] + 6, q[1] - 14), "atan ~{μ}", anchor="start", size=15)

    q = P(x_out)
    c.text((q[0] + 10, q[1] + 4), "*{x}_{1}", color=sd.VERMILION, anchor="start")
    q = P(y_out)
    c.text((q[0] + 14, q[1] - 20), "prox_{~{K}_{μ}}(*{x}_{1})", color=sd.VERMILION, anchor="start")
    q = P(x_in)
    c.text((q[0] - 10, q[1] - 12), "*{x}_{2} = prox_{~{K}_{μ}}(*{x}_{2})", color=sd.GREEN, anchor="end")
    q = P(x_pol)
    c.text((q[0] + 10, q[1] + 10), "*{x}_{3}", color=sd.PURPLE, anchor="start")
    c.text((apex[0] - 24, apex[1] - 34), "prox_{~{K}_{μ}}(*{x}_{3}) = 0", color=sd.PURPLE, anchor="end")
    c.save(path)


if __name__ == "__main__":
    main()
