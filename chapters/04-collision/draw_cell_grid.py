"""Figure ch04_cell_grid (chapter 4): the uniform grid of cell lists of the broad phase.

A monolayer of spheres (all centres in one plane, so that the grid has a single layer of cells,
n_z = 1) is binned exactly as grbd::collision::CellGrid::build does it (lib/src/collision/
broad_phase.cpp): the grid starts at the lower corner of the bounding box of the centres, the cell
edge is h = (2 r_max + margin)(1 + 10⁻⁶), and there are floor(extent/h) + 1 cells per axis. For
one sphere it shows what CellGrid::find_pairs does: its own cell and the forward neighbours of
the half shell, (i + 1, j) and the row (i − 1 … i + 1, j + 1) (the four cells of the layer k + 1
that complete the 13 of three dimensions do not exist here), the distance tests made from its
cell, and the candidate pairs, |c_i − c_j| < r_i + r_j + margin. The pairs with spheres of the
four backward neighbours are found when those cells are processed, from their own half shells.

Usage: python3 draw_cell_grid.py OUTPUT.svg   (writes that file only)
"""

import math
import os
import random
import sys

sys.dont_write_bytecode = True
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "common", "drawing"))

import svgdraw as sd  # noqa: E402

N = 25
MARGIN = 0.12
R_MIN, R_MAX = 0.3, 0.5
BOX = (5.6, 5.2)
SEED = 782


def spheres():
    """N non-overlapping discs in BOX, radii uniform in [R_MIN, R_MAX], by random sequential
    addition with a fixed seed."""
    rng = random.Random(SEED)
    out = []
    while len(out) < N:
        r = rng.uniform(R_MIN, R_MAX)
        c = (rng.uniform(r, BOX[0] - r), rng.uniform(r, BOX[1] - r))
        if all(math.hypot(c[0] - d[0], c[1] - d[1]) >= r + s for d, s in out):
            out.append((c, r))
    return out


class Grid:
    """CellGrid::build in two dimensions (one layer of cells)."""

    def __init__(self, balls, margin):
        r_max = max(r for _, r in balls)
        self.lo = (min(c[0] for c, _ in balls), min(c[1] for c, _ in balls))
        hi = (max(c[0] for c, _ in balls), max(c[1] for c, _ in balls))
        self.h = (2.0 * r_max + margin) * (1.0 + 1e-6)
        self.dims = tuple(int(math.floor((hi[d] - self.lo[d]) / self.h)) + 1 for d in range(2))
        cells = self.dims[0] * self.dims[1]
        assert cells <= 2 * len(balls) + 64  # no enlargement of h for a sparse box here

    def cell(self, c):
        """(i, j) of the centre c: floor((c − lo)/h), clamped to the grid."""
        return tuple(min(max(int((c[d] - self.lo[d]) / self.h), 0), self.dims[d] - 1) for d in range(2))


def main() -> None:
    path = sd.output_path(sys.argv, "draw_cell_grid.py")
    balls = spheres()
    grid = Grid(balls, MARGIN)
    cell_of = [grid.cell(c) for c, _ in balls]

    def reported(a, b):
        (ca, ra), (cb, rb) = balls[a], balls[b]
        return math.hypot(cb[0] - ca[0], cb[1] - ca[1]) < ra + rb + MARGIN

    forward = [(1, 0), (-1, 1), (0, 1), (1, 1)]
    backward = [(-dx, -dy) for dx, dy in forward]

    # The highlighted sphere: one in an inner cell with candidates both in its half shell and in
    # the backward neighbours; of those, one in the rightmost inner column (room for the labels),
    # then the one with most candidates, then the first.
    def score(a):
        i, j = cell_of[a]
        if not (0 < i < grid.dims[0] - 1 and 0 < j < grid.dims[1] - 1):
            return (-1, 0, 0)
        hits = [b for b in range(N) if b != a and reported(a, b)]
        fwd = [b for b in hits if (cell_of[b][0] - i, cell_of[b][1] - j) in forward + [(0, 0)]]
        return (1 if fwd and len(fwd) < len(hits) else 0, i, len(hits), -a)

    star = max(range(N), key=score)
    si, sj = cell_of[star]
    shell = [(si, sj)] + [(si + dx, sj + dy) for dx, dy in forward]
    back = [(si + dx, sj + dy) for dx, dy in backward]

    # Pixels: y up in the grid, down on the canvas; the grid on the left, labels on the right.
    scale = 66.0
    width, height = 640, 480
    gx, gy = grid.dims[0] * grid.h, grid.dims[1] * grid.h
    x0 = 48.0 + R_MAX * scale - grid.lo[0] * scale
    y0 = 0.5 * (height + gy * scale) + grid.lo[1] * scale - 6.0

    def px(p):
        return (x0 + scale * p[0], y0 - scale * p[1])

    def cell_rect(i, j):
        a = px((grid.lo[0] + i * grid.h, grid.lo[1] + (j + 1) * grid.h))
        return a[0], a[1], grid.h * scale, grid.h * scale

    c = sd.Canvas(width, height, title="The uniform cell grid of the broad phase and the half shell of one cell")
    hatch = c.hatch_pattern("backward", sd.LIGHT_GREY, spacing=8.0, width=1.2)

    c.comment("highlighted cells: own cell, forward neighbours, backward neighbours")
    for k, (i, j) in enumerate(shell):
        x, y, w, hh = cell_rect(i, j)
        c.rect(x, y, w, hh, fill=sd.ORANGE, fill_opacity=0.42 if k == 0 else 0.17)
    for i, j in back:
        x, y, w, hh = cell_rect(i, j)
        c.rect(x, y, w, hh, fill=hatch)

    c.comment("the grid")
    for i in range(grid.dims[0] + 1):
        x = grid.lo[0] + i * grid.h
        c.line(px((x, grid.lo[1])), px((x, grid.lo[1] + gy)), stroke=sd.GREY, width=0.9)
    for j in range(grid.dims[1] + 1):
        y = grid.lo[1] + j * grid.h
        c.line(px((grid.lo[0], y)), px((grid.lo[0] + gx, y)), stroke=sd.GREY, width=0.9)
    # The outline of the half shell.
    x, y, w, hh = cell_rect(si, sj)
    c.rect(x, y, w, hh, stroke=sd.VERMILION, width=2.0)

    c.comment("distance tests from the highlighted sphere's cell, and the candidate pairs")
    cs = balls[star][0]
    for b in range(N):
        if b == star:
            continue
        in_shell = cell_of[b] in shell
        if in_shell and not reported(star, b):
            c.line(px(cs), px(balls[b][0]), stroke=sd.BLACK, width=0.8)

    c.comment("the spheres")
    for b, (centre, r) in enumerate(balls):
        if b == star:
            c.circle(px(centre), r * scale, fill=sd.ORANGE, fill_opacity=0.85, stroke=sd.BLACK, width=1.4)
        else:
            c.circle(px(centre), r * scale, fill="#dcdcdc", fill_opacity=0.8, stroke=sd.BLACK, width=1.0)
    for b in range(N):
        if b != star and reported(star, b):
            c.line(px(cs), px(balls[b][0]), stroke=sd.VERMILION, width=2.4,
                   dash=None if cell_of[b] in shell else (6, 4))
    for b, (centre, r) in enumerate(balls):
        c.dot(px(centre), r=2.4 if b != star else 3.2, stroke="none")

    # Cell coordinates along the edges, outside the spheres that stick out of the grid.
    pad = R_MAX * scale + 10.0
    for i in range(grid.dims[0]):
        p = px((grid.lo[0] + (i + 0.5) * grid.h, grid.lo[1]))
        c.text((p[0], p[1] + pad), f"{i}", size=14, color=sd.GREY, halo=False)
    p = px((grid.lo[0] + gx, grid.lo[1]))
    c.text((p[0] + 8, p[1] + pad), "~{i}", size=15, color=sd.GREY, halo=False, anchor="start")
    for j in range(grid.dims[1]):
        p = px((grid.lo[0], grid.lo[1] + (j + 0.5) * grid.h))
        c.text((p[0] - pad, p[1]), f"{j}", size=14, color=sd.GREY, halo=False)
    p = px((grid.lo[0], grid.lo[1] + gy))
    c.text((p[0] - pad, p[1] - 10), "~{j}", size=15, color=sd.GREY, halo=False)

    # The cell edge h, over the top row.
    top = grid.lo[1] + gy
    a = px((grid.lo[0], top))
    b = px((grid.lo[0] + grid.h, top))
    yd = a[1] - 14
    c.line((a[0], a[1] - 4), (a[0], yd - 6), stroke=sd.BLACK, width=0.8)
    c.line((b[0], b[1] - 4), (b[0], yd - 6), stroke=sd.BLACK, width=0.8)
    m = (0.5 * (a[0] + b[0]), yd)
    c.arrow(m, (a[0], yd), width=1.0, head=8)
    c.arrow(m, (b[0], yd), width=1.0, head=8)
    c.text((b[0] + 8, yd), "~{h} ≥ 2~{r}_{max} + margin", anchor="start", valign="middle")

    # Labels of the cells, right of the grid, with leaders to the cells.
    right = px((grid.lo[0] + gx, 0))[0] + R_MAX * scale + 8.0

    def leader(cell, lines, color, fx=0.5, fy=0.5):
        x, y, w, hh = cell_rect(*cell)
        target = (x + fx * w, y + fy * hh)
        c.line(target, (right - 6, target[1]), stroke=color, width=1.2)
        c.dot(target, r=2.6, color=color, stroke="none")
        for k, text in enumerate(lines):
            c.text((right, target[1] + 18 * (k - 0.5 * (len(lines) - 1))), text, anchor="start")

    leader((si + 1, sj + 1), ["forward", "neighbours"], sd.ORANGE, fy=0.25)
    leader((si, sj), ["own cell"], sd.VERMILION, fx=0.75, fy=0.15)
    leader((si + 1, sj - 1), ["backward", "neighbours"], sd.GREY, fy=0.75)
    c.save(path)


if __name__ == "__main__":
    main()
