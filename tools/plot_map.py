#!/usr/bin/env python3
"""Top view of a ctlio map (ctlio_odometry --save_map) with the trajectory on it.

usage: plot_map.py MAP.pcd|MAP.ply TRAJECTORY.tum OUT.png [--voxel M] [--title T]

MAP is read here without extra packages: PCD (DATA ascii or binary) and PLY (ascii or
binary_little_endian/big_endian), the x y z fields. The picture is a height raster: every pixel
shows the highest map point above it, coloured by that height (the 1st-99th percentile range, so
a few stray points do not wash out the colours), white where there is none; so roofs, tree
crowns and walls stand out from the ground. Pixels are the map voxel (--voxel, default 0.2 m) or
coarser, at most about 2000 pixels across; when the map is much larger than the trajectory (a
lidar sees ~100 m around a short path) a second panel shows the square 20 m around the
trajectory at the voxel size. The trajectory (TUM: t x y z qx qy qz qw) is drawn on top in red
over white, its start marked. Axes in metres, equal aspect.
Exit code 3 if matplotlib is missing (the caller reports that no picture was written).
"""
import argparse
import os
import sys

try:
    import numpy as np
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    sys.stderr.write("matplotlib/numpy are not installed (Debian: apt install python3-matplotlib)\n")
    sys.exit(3)

PCD_TYPES = {("F", 4): "f4", ("F", 8): "f8", ("I", 1): "i1", ("I", 2): "i2", ("I", 4): "i4",
             ("I", 8): "i8", ("U", 1): "u1", ("U", 2): "u2", ("U", 4): "u4", ("U", 8): "u8"}
PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "i2",
             "int16": "i2", "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4",
             "uint": "u4", "uint32": "u4", "float": "f4", "float32": "f4", "double": "f8",
             "float64": "f8"}


def read_header(f, last):
    """Header lines up to and including the one starting with `last`; the data follows."""
    lines = []
    while True:
        raw = f.readline()
        if not raw:
            raise ValueError("no '%s' line: not a map file" % last)
        line = raw.decode("ascii", "replace").strip()
        lines.append(line)
        if line.split()[:1] == [last]:
            return lines


def read_pcd(path):
    with open(path, "rb") as f:
        header = {}
        for line in read_header(f, "DATA"):
            if line and not line.startswith("#"):
                key, *args = line.split()
                header[key] = args
        names = header["FIELDS"]
        counts = [int(c) for c in header.get("COUNT", ["1"] * len(names))]
        n = int(header.get("POINTS", [0])[0]) or int(header["WIDTH"][0]) * int(header["HEIGHT"][0])
        kind = header["DATA"][0]
        if kind == "ascii":
            values = np.loadtxt(f, ndmin=2)
            columns = np.cumsum([0] + counts)
            return np.stack([values[:, columns[names.index(a)]] for a in "xyz"], axis=1)
        if kind != "binary":
            raise ValueError("%s: DATA %s is not read here (ascii or binary)" % (path, kind))
        dtype = np.dtype([(name, "<" + PCD_TYPES[(t, int(s))], (c,) if c > 1 else ())
                          for name, s, t, c in zip(names, header["SIZE"], header["TYPE"], counts)])
        data = np.frombuffer(f.read(n * dtype.itemsize), dtype=dtype, count=n)
    return np.stack([data[a].astype(float) for a in "xyz"], axis=1)


def read_ply(path):
    with open(path, "rb") as f:
        lines = read_header(f, "end_header")
        fmt = next(l.split()[1] for l in lines if l.startswith("format"))
        props, n, in_vertex = [], 0, False
        for line in lines:
            words = line.split()
            if words[:1] == ["element"]:
                in_vertex = words[1] == "vertex"
                if in_vertex:
                    n = int(words[2])
                elif not props:
                    raise ValueError("%s: the vertex element must come first" % path)
            elif words[:1] == ["property"] and in_vertex:
                props.append((words[-1], PLY_TYPES[words[1]]))
        if fmt == "ascii":
            values = np.loadtxt(f, ndmin=2, max_rows=n)
            names = [p[0] for p in props]
            return np.stack([values[:, names.index(a)] for a in "xyz"], axis=1)
        endian = "<" if fmt == "binary_little_endian" else ">"
        dtype = np.dtype([(name, endian + t) for name, t in props])
        data = np.frombuffer(f.read(n * dtype.itemsize), dtype=dtype, count=n)
    return np.stack([data[a].astype(float) for a in "xyz"], axis=1)


def read_tum(path):
    if not os.path.exists(path):
        return np.zeros((0, 3))
    rows = [l.split() for l in open(path) if l.strip() and not l.startswith("#")]
    return np.array([[float(v) for v in r[1:4]] for r in rows if len(r) >= 8]).reshape(-1, 3)


def height_raster(points, lo, hi, pixel):
    """The highest z over every pixel of [lo, hi] (NaN where no point), its extent for imshow."""
    shape = np.maximum(np.ceil((hi - lo) / pixel).astype(int), 1)  # (nx, ny)
    raster = np.full((shape[1], shape[0]), -np.inf)
    inside = np.all((points[:, :2] >= lo) & (points[:, :2] < lo + shape * pixel), axis=1)
    p = points[inside]
    if len(p):
        ix = np.clip(((p[:, 0] - lo[0]) / pixel).astype(int), 0, shape[0] - 1)
        iy = np.clip(((p[:, 1] - lo[1]) / pixel).astype(int), 0, shape[1] - 1)
        np.maximum.at(raster, (iy, ix), p[:, 2])
    raster[np.isinf(raster)] = np.nan
    hi = lo + shape * pixel
    return raster, (lo[0], hi[0], lo[1], hi[1])


def draw(ax, points, path, lo, hi, pixel, z_range, title):
    cmap = matplotlib.colormaps["viridis"].copy()
    cmap.set_bad("white")
    raster, extent = height_raster(points, lo, hi, pixel)
    image = ax.imshow(raster, origin="lower", extent=extent, cmap=cmap, vmin=z_range[0],
                      vmax=z_range[1], interpolation="nearest")
    if len(path):
        ax.plot(path[:, 0], path[:, 1], color="white", lw=3.0)
        ax.plot(path[:, 0], path[:, 1], color="#d62728", lw=1.4, label="trajectory (lidar)")
        ax.plot(path[0, 0], path[0, 1], "o", color="#d62728", mec="white", ms=7, label="start")
        ax.legend(loc="upper right", fontsize=8)
    ax.set_xlim(extent[0], extent[1])
    ax.set_ylim(extent[2], extent[3])
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title, fontsize=10)
    return image


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("map")
    parser.add_argument("trajectory")
    parser.add_argument("png")
    parser.add_argument("--voxel", type=float, default=0.2)
    parser.add_argument("--title", default="")
    args = parser.parse_args()
    points = read_ply(args.map) if args.map.lower().endswith(".ply") else read_pcd(args.map)
    points = points[np.all(np.isfinite(points), axis=1)]
    path = read_tum(args.trajectory)
    if len(points) == 0 and len(path) == 0:
        sys.stderr.write("%s: empty map and no trajectory\n" % args.map)
        return 1
    both = np.vstack([points[:, :2], path[:, :2]])
    lo, hi = both.min(axis=0) - 1.0, both.max(axis=0) + 1.0
    pixel = max(args.voxel, float((hi - lo).max()) / 2000.0)
    z_range = (np.percentile(points[:, 2], [1, 99]) if len(points) else np.array([0.0, 1.0]))
    z_range[1] = max(z_range[1], z_range[0] + 1e-3)
    # The surroundings of the trajectory at the voxel size too, when the whole map is much
    # larger (a lidar sees ~100 m around a path of a few tens): a square 20 m beyond the path.
    zoom = None
    if len(path):
        centre = 0.5 * (path[:, :2].min(axis=0) + path[:, :2].max(axis=0))
        half = 0.5 * float((path[:, :2].max(axis=0) - path[:, :2].min(axis=0)).max()) + 20.0
        if 2.0 * half < 0.6 * float((hi - lo).max()):
            zoom = (centre - half, centre + half)
    panels = 2 if zoom else 1
    dpi = int(os.environ.get("CTLIO_PLOT_DPI", "150"))
    aspect = (hi[1] - lo[1]) / (hi[0] - lo[0])
    height = min(max(7.0 * aspect, 4.0), 12.0) + 1.0
    fig, axes = plt.subplots(1, panels, figsize=(7.0 * panels + 1.5, height), dpi=dpi,
                             layout="constrained")
    axes = np.atleast_1d(axes)
    image = draw(axes[0], points, path, lo, hi, pixel, z_range,
                 "%d map points, %.2f m voxels, %.2f m pixels" % (len(points), args.voxel, pixel))
    if zoom:
        draw(axes[1], points, path, zoom[0], zoom[1], args.voxel, z_range,
             "around the trajectory, %.2f m pixels" % args.voxel)
    fig.colorbar(image, ax=list(axes), shrink=0.8, label="height of the highest point [m]")
    fig.suptitle(args.title or os.path.basename(args.map), fontsize=11)
    fig.savefig(args.png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
