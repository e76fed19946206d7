#!/usr/bin/env python3
"""Pictures of the micromechanical analysis of one grainlab results folder (PNG in DIR/plots).

Usage: plot_micro.py DIR     (run by `grainlab analyse DIR` after it wrote DIR/micro/analysis.*)

rose_start.png, rose_peak.png, rose_end.png
    Rose diagrams at the start of shearing, at the peak of q/p and at the end: the density of
    contact normals E(n) [1/sr] (top) and the mean normal force per orientation [N] (bottom), in
    the axial x-z plane, the lateral x-y plane and in 3D. The planar roses count the contacts
    whose normal lies within 15 deg of the plane (n and -n both), in 10-deg sectors, and show the
    second-order fit (1 + a^r:nn)/4pi and f0 (1 + a^n:nn) as a line: a section of the 3D
    distribution, not a projection. The 3D view colours the orientation classes (24 N^2 patches
    of the unit sphere) by their contact density and mean normal force (grey: no contact).
micro_anisotropy.png
    a_r, a_n, a_t (and a_v) against axial strain; q/p measured beside q/p rebuilt by the
    stress-force-fabric relation (full and first order) and 2/5 (a_r + a_n + 3/2 a_t); Z and the
    mechanical Z_mech with the rattler fraction.
Definitions: docs/micromechanics.md."""
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

SLAB_DEG = 15.0
SECTOR_DEG = 10.0


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return rows


def column(rows, name):
    return np.array([float(r[name]) if r.get(name, "") != "" else np.nan for r in rows])


def save(fig, path):
    tmp = path + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    plt.close(fig)
    os.replace(tmp, path)


def particle_contacts(micro, index):
    """Normals and normal forces of the particle-particle contacts of one snapshot."""
    normals, fn = [], []
    for r in read_csv(os.path.join(micro, "contacts_%04d.csv" % index)):
        if r["b"].startswith("w"):
            continue
        n = np.array([float(r["nx"]), float(r["ny"]), float(r["nz"])])
        f = np.array([float(r["fx"]), float(r["fy"]), float(r["fz"])])
        n /= np.linalg.norm(n)
        normals.append(n)
        fn.append(f @ n)
    return np.array(normals).reshape(-1, 3), np.array(fn)


def fitted(snapshot, key, scale, directions):
    """scale * (1 + a:nn) of the snapshot's tensor `key` (None when not measured)."""
    a = snapshot.get(key)
    if a is None or scale is None:
        return None
    t = np.array(a["tensor"])
    return scale * (1.0 + np.einsum("ki,ij,kj->k", directions, t, directions))


def planar_rose(ax_count, ax_force, normals, fn, snapshot, plane):
    """Sectors of one plane: (horizontal axis, vertical axis, normal axis) indices."""
    h, v, off = plane
    both = np.vstack([normals, -normals])
    forces = np.concatenate([fn, fn])
    in_slab = np.abs(both[:, off]) < math.sin(math.radians(SLAB_DEG))
    theta = np.arctan2(both[in_slab, v], both[in_slab, h]) % (2 * math.pi)
    edges = np.radians(np.arange(0.0, 360.0 + SECTOR_DEG, SECTOR_DEG))
    counts, _ = np.histogram(theta, bins=edges)
    # Solid angle of a sector of the slab: dtheta * 2 sin(slab); 2 Nc entries in all.
    total = max(2 * len(normals), 1)
    density = counts / (total * np.diff(edges) * 2 * math.sin(math.radians(SLAB_DEG)))
    sums, _ = np.histogram(theta, bins=edges, weights=forces[in_slab])
    with np.errstate(invalid="ignore", divide="ignore"):
        mean_force = np.where(counts > 0, sums / np.maximum(counts, 1), np.nan)
    centres = 0.5 * (edges[:-1] + edges[1:])
    width = np.radians(SECTOR_DEG)
    ax_count.bar(centres, density, width=width, alpha=0.55, edgecolor="k", linewidth=0.3)
    seen = counts > 0  # a sector without contacts has no mean force: no bar
    ax_force.bar(centres[seen], mean_force[seen], width=width, alpha=0.55, color="tab:red", edgecolor="k",
                 linewidth=0.3)
    phi = np.linspace(0.0, 2 * math.pi, 361)
    d = np.zeros((phi.size, 3))
    d[:, h], d[:, v] = np.cos(phi), np.sin(phi)
    # A strongly anisotropic second-order expansion can dip below zero; a polar axis would draw a
    # negative radius on the opposite side, so the fits are drawn clipped at zero.
    e_fit = fitted(snapshot, "a_r", 1.0 / (4 * math.pi), d)
    f_fit = fitted(snapshot, "a_n", snapshot.get("f0"), d)
    e_fit = None if e_fit is None else np.maximum(e_fit, 0.0)
    f_fit = None if f_fit is None else np.maximum(f_fit, 0.0)
    if e_fit is not None:
        ax_count.plot(phi, e_fit, "k-", lw=1.3, label="(1 + a^r:nn)/4pi")
        ax_count.plot(phi, np.full_like(phi, 1.0 / (4 * math.pi)), "k:", lw=0.8, label="isotropic")
    if f_fit is not None:
        ax_force.plot(phi, f_fit, "k-", lw=1.3, label="f0 (1 + a^n:nn)")
    names = "xyz"
    for ax in (ax_count, ax_force):
        ax.set_xticks(np.radians([0, 90, 180, 270]))
        ax.set_xticklabels([names[h], names[v], "-" + names[h], "-" + names[v]])
        ax.tick_params(labelsize=7)


def rose_3d(fig, ax, classes, value, title):
    """The orientation classes as patches of the unit sphere, coloured by their value."""
    vals = column(classes, value)
    if not np.isfinite(vals).any():
        ax.set_title(title + " (not measured)", fontsize=8)
        return
    norm = matplotlib.colors.Normalize(vmin=np.nanmin(vals), vmax=np.nanmax(vals))
    cmap = plt.get_cmap("viridis")
    polys, colours = [], []
    for r, v in zip(classes, vals):
        polys.append(np.array([[float(r["c%d%s" % (c, x)]) for x in "xyz"] for c in range(4)]))
        colours.append(cmap(norm(v)) if np.isfinite(v) else (0.85, 0.85, 0.85, 1.0))  # grey: no contact
    ax.add_collection3d(Poly3DCollection(polys, facecolors=colours, edgecolors="k", linewidths=0.1))
    for set_lim in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
        set_lim(-1, 1)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=20, azim=-60)
    ax.set_xlabel("x", fontsize=7)
    ax.set_ylabel("y", fontsize=7)
    ax.set_zlabel("z (axial)", fontsize=7)
    ax.tick_params(labelsize=5)
    ax.set_title(title, fontsize=8)
    bar = fig.colorbar(matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.6, pad=0.12)
    bar.ax.tick_params(labelsize=6)


def rose_figure(micro, snapshot, label, path):
    index = snapshot["index"]
    normals, fn = particle_contacts(micro, index)
    classes = read_csv(os.path.join(micro, "classes_%04d.csv" % index))
    fig = plt.figure(figsize=(11, 7.2))
    grid = [[fig.add_subplot(2, 3, 1 + r * 3 + c, projection="polar") for c in range(2)] for r in range(2)]
    planar_rose(grid[0][0], grid[1][0], normals, fn, snapshot, (0, 2, 1))
    planar_rose(grid[0][1], grid[1][1], normals, fn, snapshot, (0, 1, 2))
    grid[0][0].set_title("contact normals, axial x-z plane [1/sr]", fontsize=8)
    grid[0][1].set_title("contact normals, lateral x-y plane [1/sr]", fontsize=8)
    grid[1][0].set_title("mean normal force, x-z plane [N]", fontsize=8)
    grid[1][1].set_title("mean normal force, x-y plane [N]", fontsize=8)
    grid[0][0].legend(fontsize=6, loc="lower left", bbox_to_anchor=(-0.25, -0.15))
    grid[1][0].legend(fontsize=6, loc="lower left", bbox_to_anchor=(-0.25, -0.15))
    rose_3d(fig, fig.add_subplot(2, 3, 3, projection="3d"), classes, "density", "contacts per class [1/sr]")
    rose_3d(fig, fig.add_subplot(2, 3, 6, projection="3d"), classes, "fn_mean", "mean normal force per class [N]")
    qp = snapshot.get("q_over_p")
    if qp is None:
        qp = snapshot.get("q_over_p_contacts")

    def fmt(v):
        return "null" if v is None else "%.3f" % v

    a = {k: (snapshot[k]["magnitude"] if snapshot.get(k) else None) for k in ("a_r", "a_n", "a_t")}
    fig.suptitle("%s of the test: snapshot %d, eps1 = %.2f %%, %d contacts, q/p = %s, a_r = %s, a_n = %s, a_t = %s"
                 % (label, index, 100 * snapshot["eps1"], snapshot["contacts"], fmt(qp), fmt(a["a_r"]),
                    fmt(a["a_n"]), fmt(a["a_t"])), fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    save(fig, path)


def anisotropy_figure(rows, path):
    eps1 = 100 * column(rows, "eps1")
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.2))
    ax = axes[0]
    for name, style in (("a_r", "o-"), ("a_n", "s-"), ("a_t", "^-"), ("a_v", "v-")):
        y = column(rows, name)
        if np.isfinite(y).any():
            ax.plot(eps1, y, style, ms=3, lw=1.2, label=name)
    ax.set_xlabel("axial strain eps1 [%]")
    ax.set_ylabel("anisotropy sign(a:s) sqrt(3/2 a:a)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax = axes[1]
    qp = column(rows, "q_over_p")
    if not np.isfinite(qp).any():
        qp = column(rows, "q_over_p_contacts")
    ax.plot(eps1, qp, "k-", lw=1.6, label="q/p measured")
    ax.plot(eps1, column(rows, "q_over_p_sff"), "o--", ms=3, label="q/p stress-force-fabric")
    ax.plot(eps1, column(rows, "q_over_p_sff_linear"), "s:", ms=3, label="q/p sff, first order")
    simple = 0.4 * (column(rows, "a_r") + column(rows, "a_n") + 1.5 * column(rows, "a_t"))
    ax.plot(eps1, simple, "x-", ms=4, lw=0.8, label="2/5 (a_r + a_n + 3/2 a_t)")
    ax.set_xlabel("axial strain eps1 [%]")
    ax.set_ylabel("q/p")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax = axes[2]
    ax.plot(eps1, column(rows, "Z"), "o-", ms=3, label="Z")
    ax.plot(eps1, column(rows, "Z_mech"), "s-", ms=3, label="Z_mech (no rattlers)")
    ax.set_xlabel("axial strain eps1 [%]")
    ax.set_ylabel("coordination number")
    twin = ax.twinx()
    twin.plot(eps1, 100 * column(rows, "rattler_fraction"), "r:", lw=1.2, label="rattlers [%]")
    twin.set_ylabel("rattler fraction [%]", color="r")
    lines = ax.get_legend_handles_labels()
    extra = twin.get_legend_handles_labels()
    ax.legend(lines[0] + extra[0], lines[1] + extra[1], fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    save(fig, path)


def main(directory):
    micro = os.path.join(directory, "micro")
    with open(os.path.join(micro, "analysis.json")) as f:
        analysis = json.load(f)
    rows = read_csv(os.path.join(micro, "analysis.csv"))
    by_index = {s["index"]: s for s in analysis["snapshots"]}
    out = os.path.join(directory, "plots")
    os.makedirs(out, exist_ok=True)
    for label in ("start", "peak", "end"):
        rose_figure(micro, by_index[analysis[label]], label, os.path.join(out, "rose_%s.png" % label))
    anisotropy_figure(rows, os.path.join(out, "micro_anisotropy.png"))
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.stderr.write(__doc__)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
