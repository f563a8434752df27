"""Figure ch01_frames (chapter 1): the inertial frame I and the body frame K of a rigid body.

The body is an ellipsoid with its centre of mass S at I_r_S; its frame K is turned against I by
the rotation A_IK = R(p) of a unit quaternion p, computed here with the formula of the chapter,
R(p) = (p0² − p_rᵀp_r) I + 2 p_r p_rᵀ + 2 p0 p̃_r. A material point P at the body-fixed offset
K_rho lies at I_r_P = I_r_S + A_IK K_rho.

Usage: python3 draw_frames.py OUTPUT.svg   (writes that file only)
"""

import math
import os
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common", "drawing"))

import svgdraw as sd  # noqa: E402

# The scene, in metres of an imaginary body; frame I: x towards the viewer, y right, z up.
I_r_S = (0.0, 3.8, 3.5)                   # centre of mass S
SEMI_AXES = (1.35, 0.8, 0.55)                # of the ellipsoid, along e_x^K, e_y^K, e_z^K
p = sd.unit((0.71, -0.14, 0.05, 0.69))       # the orientation of K: a unit quaternion, scalar first
A_IK = sd.rotation_from_quaternion(p)
# The material point P on the surface: a direction in K, scaled onto the ellipsoid.
K_dir = (-0.95, -0.56, -0.05)
t = 1.0 / math.sqrt(sum((d / a) ** 2 for d, a in zip(K_dir, SEMI_AXES)))
K_rho = sd.scale(t, K_dir)
I_rho = sd.matvec(A_IK, K_rho)
I_r_P = sd.add(I_r_S, I_rho)

cam = sd.Camera(azimuth=28.0, elevation=18.0, scale=78.0, origin=(128.0, 428.0))


def to_K(x):
    """Coordinates in K of the point x (in I): A_IKᵀ (x − I_r_S)."""
    d = sd.sub(x, I_r_S)
    return tuple(sd.dot(sd.column(A_IK, j), d) for j in range(3))


def hidden(x) -> bool:
    """Whether the body hides the point x: x inside it, or the ray from x to the viewer meets it."""
    xk = to_K(x)
    vk = to_K(sd.add(I_r_S, cam.view))  # the view direction in K
    a2 = [s * s for s in SEMI_AXES]
    c = sum(xk[i] ** 2 / a2[i] for i in range(3)) - 1.0
    if c < -1e-9:
        return True
    qa = sum(vk[i] ** 2 / a2[i] for i in range(3))
    qb = 2.0 * sum(xk[i] * vk[i] / a2[i] for i in range(3))
    disc = qb * qb - 4.0 * qa * c
    if disc <= 0.0:
        return False
    s_far = (-qb + math.sqrt(disc)) / (2.0 * qa)
    s_near = (-qb - math.sqrt(disc)) / (2.0 * qa)
    return s_far > 1e-6 and s_near > 1e-6 or (c < 1e-9 and s_far > 1e-3)


def visible_runs(a, b, samples=240):
    """The sub-segments of the segment a–b (points in I) that the body does not hide."""
    runs, start = [], None
    for k in range(samples + 1):
        s = k / samples
        x = sd.lerp(a, b, s)
        if not hidden(x):
            if start is None:
                start = s
        elif start is not None:
            runs.append((start, (k - 1) / samples))
            start = None
    if start is not None:
        runs.append((start, 1.0))
    return [(sd.lerp(a, b, s0), sd.lerp(a, b, s1), s1 == 1.0) for s0, s1 in runs if s1 > s0]


def vector(canvas, a, b, color, width, layer, dash=None):
    """A vector from a to b (points in I). layer 'under' draws all of it (the body, drawn
    translucent over it, then fades what it hides); layer 'over' draws the visible parts again."""
    if layer == "under":
        canvas.arrow(cam.project(a), cam.project(b), color=color, width=width, dash=dash)
        return
    for u, v, at_tip in visible_runs(a, b):
        if at_tip:
            canvas.arrow(cam.project(u), cam.project(v), color=color, width=width, dash=dash)
        else:
            canvas.line(cam.project(u), cam.project(v), stroke=color, width=width, dash=dash, cap="butt")


def ellipsoid_outline():
    """The silhouette of the ellipsoid: the image of the unit circle under a factor L of
    M = P A D² Aᵀ Pᵀ, P the projection onto the screen (rows: right, up)."""
    rows = (cam.right, cam.up)
    # B = P A D, M = B Bᵀ
    B = [[sd.dot(rows[i], sd.column(A_IK, j)) * SEMI_AXES[j] for j in range(3)] for i in range(2)]
    m11 = sum(v * v for v in B[0])
    m12 = sum(u * v for u, v in zip(B[0], B[1]))
    m22 = sum(v * v for v in B[1])
    l11 = math.sqrt(m11)
    l21 = m12 / l11
    l22 = math.sqrt(m22 - l21 * l21)
    cx, cy = cam.project(I_r_S)
    pts = []
    for k in range(180):
        t = 2.0 * math.pi * k / 180
        u, v = math.cos(t), math.sin(t)
        x, y = l11 * u, l21 * u + l22 * v
        pts.append((cx + cam.scale * x, cy - cam.scale * y))
    return pts


def section(i, j):
    """The principal section of the body in the plane of e_i^K, e_j^K, split into the arcs in
    front (visible) and behind, as lists of pixel polylines."""
    front, back = [], []
    current, current_front = [], None
    for k in range(241):
        t = 2.0 * math.pi * k / 240
        xk = [0.0, 0.0, 0.0]
        xk[i] = SEMI_AXES[i] * math.cos(t)
        xk[j] = SEMI_AXES[j] * math.sin(t)
        normal_K = [xk[m] / SEMI_AXES[m] ** 2 for m in range(3)]
        is_front = sd.dot(sd.matvec(A_IK, normal_K), cam.view) > 0.0
        x = sd.add(I_r_S, sd.matvec(A_IK, xk))
        if current_front is None or is_front == current_front:
            current.append(cam.project(x))
        else:
            current.append(cam.project(x))
            (front if current_front else back).append(current)
            current = [cam.project(x)]
        current_front = is_front
    (front if current_front else back).append(current)
    return front, back


def main() -> None:
    path = sd.output_path(sys.argv, "draw_frames.py")
    c = sd.Canvas(640, 480, title="The inertial frame I and the body frame K of a rigid body")
    O = (0.0, 0.0, 0.0)
    axis_len = 1.5
    K_axis_len = [SEMI_AXES[0] + 0.75, SEMI_AXES[1] + 1.3, SEMI_AXES[2] + 0.9]
    K_axes = [sd.column(A_IK, j) for j in range(3)]
    K_tips = [sd.add(I_r_S, sd.scale(K_axis_len[j], K_axes[j])) for j in range(3)]
    K_colors = [sd.VERMILION, sd.GREEN, sd.BLUE]

    # Frame I: thin black axes at O.
    c.comment("inertial frame I")
    names = ("x", "y", "z")
    I_label_offsets = [(-14, 6), (10, 14), (-4, -14)]
    for j in range(3):
        e = [0.0, 0.0, 0.0]
        e[j] = axis_len
        tip = cam.project(e)
        c.arrow(cam.project(O), tip, color=sd.BLACK, width=1.3)
        dx, dy = I_label_offsets[j]
        c.text((tip[0] + dx, tip[1] + dy), f"*{{e}}_{{{names[j]}}}^{{I}}", anchor="middle")
    o_px = cam.project(O)
    c.dot(o_px, r=3.0)
    c.text((o_px[0] - 14, o_px[1] + 4), "~{O}")
    c.text((o_px[0] + 2, o_px[1] + 44), "frame ~{I}", color=sd.BLACK)

    # Under the body: everything it may hide, faded by the translucent body drawn over it.
    c.comment("the parts that the body hides")
    back_arcs = []
    for i, j in ((0, 1), (1, 2), (0, 2)):
        front, back = section(i, j)
        back_arcs += back
    for arc in back_arcs:
        c.polyline(arc, stroke=sd.GREY, width=0.9, dash=(4, 3))
    for j in range(3):
        vector(c, I_r_S, K_tips[j], K_colors[j], 1.6, "under")
    vector(c, O, I_r_S, sd.BLUE, 2.2, "under")
    vector(c, I_r_S, I_r_P, sd.PURPLE, 2.2, "under")

    # The body.
    c.comment("the rigid body, an ellipsoid")
    fill = c.radial_gradient("body-shade", [(0.0, "#fdf3df", 1.0), (0.55, "#f3d9a6", 1.0),
                                            (1.0, "#c9a467", 1.0)], cx=0.38, cy=0.3, r=0.8)
    c.polygon(ellipsoid_outline(), fill=fill, fill_opacity=0.6, stroke=sd.BLACK, width=1.3)
    for i, j in ((0, 1), (1, 2), (0, 2)):
        front, back = section(i, j)
        for arc in front:
            c.polyline(arc, stroke=sd.GREY, width=0.9)

    # Over the body: the visible parts.
    s_px = cam.project(I_r_S)
    p_px = cam.project(I_r_P)
    c.comment("frame K, the vectors, the points")
    vector(c, O, I_r_S, sd.BLUE, 2.2, "over")
    vector(c, O, I_r_P, sd.GREEN, 2.2, "over")
    for j in range(3):
        vector(c, I_r_S, K_tips[j], K_colors[j], 1.6, "over")
    c.arrow(s_px, p_px, color=sd.PURPLE, width=2.2)  # drawn through the body: the key vector
    c.dot(s_px, r=3.6)
    c.dot(p_px, r=3.6)

    # Labels.
    K_label_offsets = [(2, 18), (16, 4), (0, -14)]
    for j in range(3):
        tip = cam.project(K_tips[j])
        dx, dy = K_label_offsets[j]
        c.text((tip[0] + dx, tip[1] + dy), f"*{{e}}_{{{names[j]}}}^{{K}}", color=K_colors[j])
    c.text((s_px[0] - 4, s_px[1] + 19), "~{S}")
    c.text((p_px[0] + 12, p_px[1] + 4), "~{P}", anchor="start")
    mid = sd.lerp(cam.project(O), s_px, 0.45)
    c.text((mid[0] + 12, mid[1] + 12), "_{I}*{r}_{S}", color=sd.BLUE, anchor="start")
    mid = sd.lerp(cam.project(O), p_px, 0.5)
    c.text((mid[0] - 12, mid[1] - 6), "_{I}*{r}_{P}", color=sd.GREEN, anchor="end")
    mid = sd.lerp(s_px, p_px, 0.5)
    c.text((mid[0] - 6, mid[1] + 18), "_{K}*{ρ}", color=sd.PURPLE, anchor="middle")
    c.text((24, 74), "frame ~{K} at ~{S}:  *{A}_{IK} = *{R}(~{p})", anchor="start")

    c.text((24, 42), "_{I}*{r}_{P} = _{I}*{r}_{S} + *{A}_{IK} _{K}*{ρ}", size=17, anchor="start")
    c.save(path)


if __name__ == "__main__":
    main()
