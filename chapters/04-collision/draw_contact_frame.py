"""Figure ch04_contact_frame (chapter 4): the contact of two spheres and its contact frame.

The conventions are those of grbd::collision (contact.hpp, narrow_phase.cpp): the normal n points
from b towards a; the closest points are r_a = c_a − r_a n and r_b = c_b + r_b n, so that
r_a − r_b = g_N n with the signed gap g_N = |c_a − c_b| − r_a − r_b (positive here: the spheres
are a little apart); the tangents t1, t2 are those of tangent_basis(n) (Exercise 4.4), computed
below with the same formula; the lever arms are ρ_a = r_a − S_a and ρ_b = r_b − S_b, the contact
points relative to the centres of mass (in the body frames they are Contact::K_rho_a, K_rho_b).

Usage: python3 draw_contact_frame.py OUTPUT.svg   (writes that file only)
"""

import math
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common", "drawing"))

import svgdraw as sd  # noqa: E402


def tangent_basis(n):
    """t1, t2 of grbd::collision::tangent_basis (solutions/04-collision/contact.cpp): Frisvad's
    basis with 1/(1 + n_z) written without cancellation on the southern hemisphere."""
    x, y, z = n
    s = x * x + y * y
    if z >= 0.0:
        a = 1.0 / (1.0 + z)
    elif s > 0.0:
        a = (1.0 - z) / s
    else:
        return (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0)
    b = -a * x * y
    return (1.0 - a * x * x, b, -x), (b, 1.0 - a * y * y, -y)


cam = sd.Camera(azimuth=70.0, elevation=20.0, scale=112.0, origin=(228.0, 318.0))

# Body b at the origin, body a along the normal, a little apart (g_N > 0).
R_A, R_B, GAP = 0.85, 1.0, 0.85
TILT = math.radians(28.0)        # of n out of the picture plane, towards the viewer
ON_SCREEN = math.radians(35.0)   # direction of n in the picture, above the horizontal
n = sd.unit(sd.add(sd.scale(math.cos(TILT), sd.add(sd.scale(math.cos(ON_SCREEN), cam.right),
                                                     sd.scale(math.sin(ON_SCREEN), cam.up))),
                   sd.scale(math.sin(TILT), cam.view)))
c_b = (0.0, 0.0, 0.0)
c_a = sd.scale(R_A + R_B + GAP, n)


def sphere_sphere(ca, ra, cb, rb):
    """grbd::collision::sphere_sphere (Exercise 4.1): normal, gap and closest points."""
    d = sd.sub(ca, cb)
    dist = sd.norm(d)
    normal = sd.scale(1.0 / dist, d) if dist > 0.0 else (0.0, 0.0, 1.0)
    return normal, dist - ra - rb, sd.sub(ca, sd.scale(ra, normal)), sd.add(cb, sd.scale(rb, normal))


def main() -> None:
    path = sd.output_path(sys.argv, "draw_contact_frame.py")
    I_n, g_N, r_a, r_b = sphere_sphere(c_a, R_A, c_b, R_B)
    t1, t2 = tangent_basis(I_n)
    assert abs(g_N - GAP) < 1e-12  # apart by GAP: g_N > 0
    # right-handed and orthonormal, as the library promises
    assert abs(sd.dot(t1, I_n)) < 1e-12 and abs(sd.norm(sd.sub(sd.cross(I_n, t1), t2))) < 1e-12

    c = sd.Canvas(640, 480, title="Two spheres a and b and their contact frame (n, t1, t2)")
    P = cam.project
    shade_a = c.radial_gradient("shade-a", [(0.0, "#ffffff", 1.0), (0.5, "#a9d3ef", 1.0),
                                            (1.0, "#4f8fbf", 1.0)])
    shade_b = c.radial_gradient("shade-b", [(0.0, "#ffffff", 1.0), (0.5, "#f6d39a", 1.0),
                                            (1.0, "#c98f2e", 1.0)])
    # The spheres are translucent, so that the points and lever arms inside show.
    c.comment("body b, then body a (nearer the viewer)")
    c.circle(P(c_b), R_B * cam.scale, fill=shade_b, fill_opacity=0.55, stroke=sd.BLACK, width=1.3)
    c.circle(P(c_a), R_A * cam.scale, fill=shade_a, fill_opacity=0.55, stroke=sd.BLACK, width=1.3)

    # The tangent plane at r_b, a translucent square spanned by t1 and t2.
    c.comment("the contact plane at r_b")
    h = 0.62
    corners = [sd.add(r_b, sd.add(sd.scale(s1 * h, t1), sd.scale(s2 * h, t2)))
               for s1, s2 in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
    c.polygon([P(x) for x in corners], fill="#9a9a9a", fill_opacity=0.22, stroke=sd.GREY, width=0.9)

    # Lever arms, dashed.
    c.comment("lever arms")
    c.arrow(P(c_a), P(r_a), color=sd.PURPLE, width=1.7, dash=(6, 4))
    c.arrow(P(c_b), P(r_b), color=sd.PURPLE, width=1.7, dash=(6, 4))

    # The contact frame at r_b.
    c.comment("contact frame")
    L = 0.72
    c.arrow(P(r_b), P(sd.add(r_b, sd.scale(L, I_n))), color=sd.VERMILION, width=2.3)
    c.arrow(P(r_b), P(sd.add(r_b, sd.scale(L, t1))), color=sd.BLUE, width=2.3)
    c.arrow(P(r_b), P(sd.add(r_b, sd.scale(L, t2))), color=sd.GREEN, width=2.3)

    # The gap: a dimension line parallel to n, beside the points.
    c.comment("the gap g_N")
    off = sd.scale(-1.0, t1)  # beside the points, on the side away from t1
    ga = sd.add(r_a, sd.scale(0.85, off))
    gb = sd.add(r_b, sd.scale(0.85, off))
    c.line(P(sd.add(r_a, sd.scale(0.12, off))), P(sd.add(r_a, sd.scale(0.93, off))), stroke=sd.GREY, width=0.8)
    c.line(P(sd.add(r_b, sd.scale(0.66, off))), P(sd.add(r_b, sd.scale(0.93, off))), stroke=sd.GREY, width=0.8)
    c.arrow(P(sd.lerp(ga, gb, 0.5)), P(ga), color=sd.BLACK, width=1.0, head=8)
    c.arrow(P(sd.lerp(ga, gb, 0.5)), P(gb), color=sd.BLACK, width=1.0, head=8)

    # Points.
    for x in (c_a, c_b, r_a, r_b):
        c.dot(P(x), r=3.4)

    # Labels.
    pa, pb = P(c_a), P(c_b)
    c.text((pa[0] + 8, pa[1] + 20), "~{S}_{a}")
    c.text((pb[0] - 8, pb[1] + 20), "~{S}_{b}")
    c.text((pa[0] + 40, pa[1] - R_A * cam.scale - 4), "body ~{a}", anchor="start")
    c.text((pb[0] - R_B * cam.scale * 0.9, pb[1] + R_B * cam.scale + 6), "body ~{b}", anchor="middle")
    tip = P(sd.add(r_b, sd.scale(L, I_n)))
    c.text((tip[0] - 2, tip[1] + 16), "*{n}", color=sd.VERMILION, anchor="start")
    tip = P(sd.add(r_b, sd.scale(L, t1)))
    c.text((tip[0] - 8, tip[1] - 10), "*{t}_{1}", color=sd.BLUE, anchor="end")
    tip = P(sd.add(r_b, sd.scale(L, t2)))
    c.text((tip[0] + 10, tip[1] + 8), "*{t}_{2}", color=sd.GREEN, anchor="start")
    ra_px, rb_px = P(r_a), P(r_b)
    c.text((ra_px[0] - 6, ra_px[1] - 14), "~{P}_{a}", anchor="end")
    c.text((rb_px[0] - 10, rb_px[1] + 20), "~{P}_{b}", anchor="end")
    m = P(sd.lerp(c_a, r_a, 0.5))
    c.text((m[0] + 12, m[1] + 4), "*{ρ}_{a}", color=sd.PURPLE, anchor="start")
    m = P(sd.lerp(c_b, r_b, 0.5))
    c.text((m[0] + 4, m[1] + 16), "*{ρ}_{b}", color=sd.PURPLE, anchor="start")
    m = P(sd.lerp(ga, gb, 0.5))
    c.text((m[0] + 10, m[1] + 4), "~{g}_{N}", anchor="start")
    c.save(path)


if __name__ == "__main__":
    main()
