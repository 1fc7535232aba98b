"""Packing metrics (named as in docs/packing.md), computed from positions and radii — independent of the solver that
produced them, so the reference and the engines' dumps are measured the same way.

* solid_fraction: sphere volume inside a horizontal slab of the bulk (away from the floor and the free
  surface by ``margin`` diameters) over the slab's volume, spheres cut exactly by the slab planes;
* coordination_number: contacts (overlap ≥ −tol·d) per particle, over particles of the bulk slab;
* contact forces (when given): mean and the histogram of f/⟨f⟩; max_overlap_ratio: δ_max/d;
* bed_height: in a periodic box, the mean free-surface height — the highest particle top in each column of
  a grid of cells about one mean diameter wide, averaged over the columns (a sphere perched on top moves it
  by one column's share, not by a diameter); without a box, the highest particle top;
* kinetic_energy: the last value of the series — translational, in every source (the engines' thermo `ke`;
  without rolling or twisting resistance a sphere rolling or spinning about its contact normal keeps its
  rotational energy indefinitely, so rotation says nothing about whether a packing has settled; a rolling law,
  where the case names one, resists the rolling but not a spin about the normal, so the same holds).
* the contact network: every particle–particle contact's branch vector (centre to centre, by minimum
  image in periodic x and y) and the fabric tensor φ_ij = (1/N_c) Σ n_i n_j of their unit vectors (Satake's,
  trace 1): ``fabric`` (3 × 3), ``fabric_zz`` and ``fabric_anisotropy`` = √(3/2 a′:a′) of the anisotropy
  tensor a′ = 15/2 (φ − I/3) of the second-order approximation of the contact-normal density in 3-D,
  E(n) = (1 + a′_ij n_i n_j)/4π (Rothenburg and Bathurst's Fourier fit for discs, carried to spheres); for a fabric symmetric about z it is a′_zz − a′_xx
  = 45/4 (φ_zz − 1/3). Wall contacts are not particle pairs and are not in it.
"""

from __future__ import annotations

import math

import numpy as np


def _cap_volume(r, lo, hi):
    """Volume of a sphere of radius r (centre at 0) between the planes t = lo and t = hi."""
    a, b = np.maximum(lo, -r), np.minimum(hi, r)
    v = math.pi * ((r * r * b - b**3 / 3.0) - (r * r * a - a**3 / 3.0))
    return np.where(b > a, v, 0.0)


def contacts(x, rad, box=None, tol=1e-9):
    """Pairs (i, j), i < j, in contact (overlap ≥ −tol·(r_i + r_j)), sorted; minimum image in x and y when
    ``box`` is the periodic (lx, ly). A k-d tree (scipy's, periodic in x and y): O(N log N)."""
    from scipy.spatial import cKDTree

    x = np.array(x, float)
    rad = np.asarray(rad, float)
    if len(x) < 2:
        return np.empty((0, 2), np.int64)
    reach = 2.0 * float(rad.max()) * (1.0 + tol)
    x[:, 2] -= x[:, 2].min()
    if box is not None:
        for k in range(2):
            x[:, k] = np.mod(x[:, k], box[k])
            x[x[:, k] >= box[k], k] = 0.0  # mod can round up to the box length
        size = [box[0], box[1], float(x[:, 2].max()) + 2.0 * reach]  # no image within reach along z
        tree = cKDTree(x, boxsize=size)
    else:
        tree = cKDTree(x)
    pairs = tree.query_pairs(reach, output_type="ndarray").astype(np.int64)
    if not len(pairs):
        return np.empty((0, 2), np.int64)
    d = minimum_image(x[pairs[:, 1]] - x[pairs[:, 0]], box)
    keep = np.linalg.norm(d, axis=1) <= (rad[pairs[:, 0]] + rad[pairs[:, 1]]) * (1.0 + tol)
    pairs = np.sort(pairs[keep], axis=1)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


def branch_vectors(x, pairs, box=None) -> np.ndarray:
    """x_j − x_i of every pair (i, j) (N_c × 3): by minimum image in x and y when ``box`` is the periodic
    (lx, ly), so a contact across the boundary is the short vector between the two spheres, never one across
    the box."""
    x = np.asarray(x, float)
    pairs = np.asarray(pairs, np.int64).reshape(-1, 2)
    return minimum_image(x[pairs[:, 1]] - x[pairs[:, 0]], box)


def minimum_image(d, box=None) -> np.ndarray:
    """Separations ``d`` (N × 3, changed in place and returned) moved by whole box lengths in x and y into
    [−L/2, L/2) when ``box`` is the periodic (lx, ly): the one minimum-image rule of the packing metrics."""
    if box is not None:
        for k in range(2):
            d[:, k] -= box[k] * np.floor(d[:, k] / box[k] + 0.5)
    return d


def fabric(branches) -> np.ndarray:
    """The fabric tensor φ_ij = (1/N_c) Σ n_i n_j of the unit contact normals n = b/|b| of the branch vectors
    ``branches`` (N_c × 3): symmetric, trace 1; NaN without contacts."""
    b = np.asarray(branches, float).reshape(-1, 3)
    if not len(b):
        return np.full((3, 3), math.nan)
    n = b / np.linalg.norm(b, axis=1)[:, None]
    return n.T @ n / len(n)


def fabric_anisotropy(phi) -> float:
    """√(3/2 a′:a′) of the anisotropy tensor a′ = 15/2 (φ − (tr φ/3) I) (see the module docstring): 0 for an
    isotropic fabric, 15/2 for every contact along one axis, 15/4 for contacts spread evenly in one plane."""
    phi = np.asarray(phi, float)
    a = 7.5 * (phi - np.trace(phi) / 3.0 * np.eye(3))
    return float(math.sqrt(1.5 * float(np.sum(a * a))))


def surface_height(x, rad, box=None) -> float:
    """The bed's free-surface height (see the module docstring)."""
    x, rad = np.asarray(x, float), np.asarray(rad, float)
    tops = x[:, 2] + rad
    if box is None:
        return float(tops.max())
    d = 2.0 * float(rad.mean())
    n = [max(1, int(box[k] / d * (1.0 + 1e-9))) for k in range(2)]  # a box of exactly k diameters: k cells
    cell = [np.floor(np.mod(x[:, k], box[k]) / box[k] * n[k]).astype(np.int64).clip(0, n[k] - 1) for k in range(2)]
    highest = np.full(n[0] * n[1], -np.inf)
    np.maximum.at(highest, cell[0] * n[1] + cell[1], tops)
    return float(highest[np.isfinite(highest)].mean())


BULK_MARGIN = 1.0  # diameters between the bulk slab and the floor / the free surface (pack and verify alike)


def compute(x, rad, box=None, floor=0.0, margin=BULK_MARGIN, forces=None, overlaps=None, ke=None) -> dict:
    x = np.asarray(x, float)
    rad = np.asarray(rad, float)
    d = 2.0 * float(rad.mean())
    top = surface_height(x, rad, box)
    z0, z1 = floor + margin * d, top - margin * d
    out = {"bed_height": top - floor, "solid_fraction": math.nan, "coordination_number": math.nan,
           "mean_contact_force": math.nan, "max_overlap_ratio": math.nan, "kinetic_energy": math.nan}
    pairs = contacts(x, rad, box)
    phi = fabric(branch_vectors(x, pairs, box))  # every particle–particle contact, not only the bulk's
    out["fabric_zz"] = float(phi[2, 2])
    out["fabric_anisotropy"] = fabric_anisotropy(phi) if len(pairs) else math.nan
    out["fabric"] = phi.tolist()
    if box is not None and z1 > z0:
        vol = float(_cap_volume(rad, z0 - x[:, 2], z1 - x[:, 2]).sum())
        out["solid_fraction"] = vol / (box[0] * box[1] * (z1 - z0))
    bulk = (x[:, 2] >= z0) & (x[:, 2] <= z1) if z1 > z0 else np.ones(len(x), bool)
    if bulk.any():
        count = np.zeros(len(x))
        np.add.at(count, pairs[:, 0], 1)
        np.add.at(count, pairs[:, 1], 1)
        out["coordination_number"] = float(count[bulk].mean())
    if forces is not None and len(forces):
        f = np.asarray(forces, float)
        out["mean_contact_force"] = float(f.mean())
    if overlaps is not None and len(overlaps):
        out["max_overlap_ratio"] = float(np.max(overlaps) / d)
    if ke is not None and len(ke):
        out["kinetic_energy"] = float(ke[-1])
    return out


def force_distribution(forces, bins: int = 20) -> dict:
    """P(f/⟨f⟩): bin centres and probability densities, and n, the number of (repulsive) contact forces they
    are drawn from."""
    f = np.asarray(forces, float)
    f = f[f > 0]
    if not f.size:
        return {"x": [], "p": [], "n": 0}
    ratio = f / f.mean()
    p, edges = np.histogram(ratio, bins=bins, range=(0.0, max(4.0, float(ratio.max()))), density=True)
    return {"x": (0.5 * (edges[1:] + edges[:-1])).tolist(), "p": p.tolist(), "n": int(f.size)}


def profile(x, rad, box, bins: int = 30) -> dict:
    """Solid fraction against height: the sphere volume in horizontal slices of the periodic box."""
    x = np.asarray(x, float)
    rad = np.asarray(rad, float)
    top = float((x[:, 2] + rad).max())
    edges = np.linspace(0.0, top, bins + 1)
    frac = []
    for lo, hi in zip(edges[:-1], edges[1:]):
        vol = float(_cap_volume(rad, lo - x[:, 2], hi - x[:, 2]).sum())
        frac.append(vol / (box[0] * box[1] * (hi - lo)))
    return {"z": (0.5 * (edges[1:] + edges[:-1])).tolist(), "solid_fraction": frac}
