"""What scripts/settling-vs-dem and scripts/incline-vs-dem share: the volume of spheres cut by a
plane, for solid fractions measured alike in both codes' outputs, and LAMMPS' text dumps."""

import math

import numpy as np


def volume_below(h, r):
    """Volume of a sphere of radius r below the plane at height h above its centre (h clipped to
    [-r, r]: none below -r, the whole sphere above r); numpy arrays or numbers."""
    h = np.clip(h, -r, r)
    return math.pi * (r + h) ** 2 * (2 * r - h) / 3.0


def read_lammps_dump(path):
    """One snapshot of a LAMMPS `dump custom` text file: a dict from each column's name to its
    values (one per atom, in the file's order)."""
    with open(path) as f:
        lines = f.readlines()
    n = int(lines[3])
    columns = lines[8].split()[2:]
    a = np.loadtxt(lines[9:9 + n], ndmin=2)
    return {c: a[:, k] for k, c in enumerate(columns)}
