"""The bad-input probe's mutations (tools/bad_input_probe.py): each a (class, name, function)
that edits a copy of a simulated recording folder, config or bag the way real recordings go wrong
(docs/user-guide/bad-input.md)."""
import os
import re
import struct


# ---------------------------------------------------------------- folder helpers
def read_lines(path):
    with open(path) as f:
        return f.read().splitlines()


def write_lines(path, lines):
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def map_csv(path, fn):
    """fn(header, rows) -> rows; rows are lists of strings."""
    lines = read_lines(path)
    rows = [l.split(",") for l in lines[1:] if l]
    write_lines(path, [lines[0]] + [",".join(r) for r in fn(lines[0], rows)])


def map_points(path, fn):
    """fn(list of [x, y, z, t]) -> list; 16-byte records float32 x y z, uint32 t."""
    data = open(path, "rb").read()
    pts = [list(struct.unpack_from("<fffI", data, i)) for i in range(0, len(data) // 16 * 16, 16)]
    pts = fn(pts)
    with open(path, "wb") as f:
        for x, y, z, t in pts:
            f.write(struct.pack("<fffI", x, y, z, int(t) & 0xFFFFFFFF))


def scan_files(folder):
    d = os.path.join(folder, "scans")
    return sorted(os.path.join(d, f) for f in os.listdir(d))


def edit_yaml(folder, old_re, new):
    p = os.path.join(folder, "ctlio_sim.yaml")
    s = open(p).read()
    s2 = re.sub(old_re, new, s, count=1)
    assert s2 != s, old_re
    open(p, "w").write(s2)


# ---------------------------------------------------------------- mutations (class, name, fn)
def folder_mutations(rng):
    m = []

    def imu(fn):
        return lambda d: map_csv(os.path.join(d, "imu.csv"), fn)

    # imu_values
    for bad in ("nan", "inf", "-inf", "1e300"):
        col, row = rng.randrange(1, 7), rng.randrange(5, 700)
        m.append(("imu_values", f"{bad}_col{col}_row{row}",
                  imu(lambda h, r, bad=bad, col=col, row=row: [
                      x if i != row else x[:col] + [bad] + x[col + 1:]
                      for i, x in enumerate(r)])))
    # imu_times
    m.append(("imu_times", "duplicates", imu(lambda h, r: [x for x in r for _ in (0, 1)])))
    swap = rng.randrange(5, 700)
    m.append(("imu_times", f"swap_rows_{swap}",
              imu(lambda h, r: r[:swap] + [r[swap + 1], r[swap]] + r[swap + 2:])))
    m.append(("imu_times", "microseconds",
              imu(lambda h, r: [[str(int(x[0]) // 1000)] + x[1:] for x in r])))
    m.append(("imu_times", "gap_1s", imu(lambda h, r: [x for x in r if not
                                                         1.5e9 <= int(x[0]) < 2.5e9])))
    m.append(("imu_times", "rate_20hz", imu(lambda h, r: r[::10])))
    m.append(("imu_times", "ends_early", imu(lambda h, r: r[:len(r) // 2])))
    m.append(("imu_times", "near_int64_max",
              imu(lambda h, r: [[str(int(x[0]) + 9223372030000000000)] + x[1:] for x in r])))
    # imu_units
    m.append(("imu_units", "accel_in_g", imu(lambda h, r: [x[:4] + [str(float(v) / 9.80665)
                                                                     for v in x[4:]] for x in r])))
    m.append(("imu_units", "accel_sign_flipped",
              imu(lambda h, r: [x[:4] + [str(-float(v)) for v in x[4:]] for x in r])))
    m.append(("imu_units", "gyro_deg_per_s", imu(lambda h, r: [[x[0]] + [str(float(v) * 57.29578)
                                                                          for v in x[1:4]] + x[4:]
                                                                for x in r])))
    m.append(("imu_units", "accel_axes_swapped",
              imu(lambda h, r: [x[:4] + [x[6], x[5], x[4]] for x in r])))
    # imu_format
    m.append(("imu_format", "garbage_line", imu(lambda h, r: r[:9] + [["abc", "def"]] + r[9:])))
    m.append(("imu_format", "missing_column", imu(lambda h, r: r[:9] + [r[9][:5]] + r[10:])))
    m.append(("imu_format", "header_only", imu(lambda h, r: [])))
    m.append(("imu_format", "missing_file", lambda d: os.remove(os.path.join(d, "imu.csv"))))

    # scan_index
    def scans_csv(fn):
        return lambda d: map_csv(os.path.join(d, "scans.csv"), fn)

    m.append(("scan_index", "duplicate_line", scans_csv(lambda h, r: r[:5] + [r[5]] + r[5:])))
    m.append(("scan_index", "swapped_lines", scans_csv(lambda h, r: r[:5] + [r[6], r[5]] + r[7:])))
    m.append(("scan_index", "start_after_end",
              scans_csv(lambda h, r: [x if i != 7 else [x[0], x[2], x[1]] + x[3:]
                                      for i, x in enumerate(r)])))
    m.append(("scan_index", "overlap",
              scans_csv(lambda h, r: [x if i != 7 else x[:2] + [str(int(x[2]) + 50_000_000)] +
                                      x[3:] for i, x in enumerate(r)])))
    m.append(("scan_index", "lidar_gap_1s", scans_csv(lambda h, r: r[:12] + r[22:])))
    m.append(("scan_index", "wrong_point_count",
              scans_csv(lambda h, r: [x if i != 4 else x[:3] + ["17"] + x[4:]
                                      for i, x in enumerate(r)])))
    m.append(("scan_index", "missing_bin", lambda d: os.remove(scan_files(d)[9])))

    # scan_points
    def pts(fn, which=None):
        def go(d):
            files = scan_files(d)
            for f in (files if which is None else [files[i] for i in which]):
                map_points(f, fn)
        return go

    nan = float("nan")
    m.append(("scan_points", "truncated_bin", lambda d: open(scan_files(d)[6], "r+b").truncate(
        16 * 1000 + 7)))
    m.append(("scan_points", "empty_bin", lambda d: open(scan_files(d)[6], "wb").close()))
    m.append(("scan_points", "some_nan", pts(lambda p: [q if i % 7 else [nan] + q[1:]
                                                          for i, q in enumerate(p)])))
    m.append(("scan_points", "all_nan_one_scan", pts(lambda p: [[nan, nan, nan, q[3]] for q in p],
                                                    [10])))
    m.append(("scan_points", "all_at_origin", pts(lambda p: [[0, 0, 0, q[3]] for q in p])))
    m.append(("scan_points", "all_far", pts(lambda p: [[1e9, 1e9, 1e9, q[3]] for q in p])))
    m.append(("scan_points", "times_zero", pts(lambda p: [q[:3] + [0] for q in p])))
    m.append(("scan_points", "times_microseconds", pts(lambda p: [q[:3] + [q[3] // 1000]
                                                                   for q in p])))
    m.append(("scan_points", "times_reversed", pts(lambda p: [q[:3] + [99_000_000 - q[3]]
                                                               for q in p])))
    m.append(("scan_points", "one_point_far_in_time",
              pts(lambda p: p[:-1] + [p[-1][:3] + [4_000_000_000]], [8])))
    for k in range(3):
        def flip(d, k=k):
            f = scan_files(d)[rng.randrange(2, 30)]
            b = bytearray(open(f, "rb").read())
            for _ in range(rng.randrange(1, 50)):
                b[rng.randrange(len(b))] = rng.randrange(256)
            open(f, "wb").write(bytes(b))
        m.append(("scan_points", f"byte_flips_{k}", flip))

    # extrinsic (ctlio_sim.yaml imu_from_lidar)
    tr = r"translation: \[0, 0, 0\]"
    qt = r"quaternion_xyzw: \[0, 0, 0, 1\]"
    m.append(("extrinsic", "nan_translation", lambda d: edit_yaml(d, tr, "translation: [.nan, 0, 0]")))
    m.append(("extrinsic", "inf_translation", lambda d: edit_yaml(d, tr, "translation: [.inf, 0, 0]")))
    m.append(("extrinsic", "nan_quaternion", lambda d: edit_yaml(d, qt, "quaternion_xyzw: [.nan, 0, 0, 1]")))
    m.append(("extrinsic", "zero_quaternion", lambda d: edit_yaml(d, qt, "quaternion_xyzw: [0, 0, 0, 0]")))
    m.append(("extrinsic", "unnormalised_quaternion",
              lambda d: edit_yaml(d, qt, "quaternion_xyzw: [0, 0, 0, 2]")))
    m.append(("extrinsic", "wrong_by_10cm", lambda d: edit_yaml(d, tr, "translation: [0.1, 0, 0]")))
    m.append(("extrinsic", "wrong_by_5deg",
              lambda d: edit_yaml(d, qt, "quaternion_xyzw: [0, 0, 0.0436194, 0.9990482]")))

    # ground_truth
    def gt(fn):
        return lambda d: map_csv(os.path.join(d, "ground_truth.csv"), fn)
    m.append(("ground_truth", "nan_row", gt(lambda h, r: r[:50] + [[r[50][0], "nan"] + r[50][2:]] +
                                            r[51:])))
    m.append(("ground_truth", "swapped_rows", gt(lambda h, r: r[:50] + [r[51], r[50]] + r[52:])))
    m.append(("ground_truth", "zero_quaternion",
              gt(lambda h, r: r[:50] + [r[50][:4] + ["0", "0", "0", "0"]] + r[51:])))
    m.append(("ground_truth", "truncated", gt(lambda h, r: r[:len(r) // 3] + [r[len(r) // 3][:3]])))

    # dataset yaml
    m.append(("dataset_yaml", "gravity_nan", lambda d: edit_yaml(d, r"gravity: [0-9.]+", "gravity: .nan")))
    m.append(("dataset_yaml", "gravity_zero", lambda d: edit_yaml(d, r"gravity: [0-9.]+", "gravity: 0")))
    m.append(("dataset_yaml", "garbage", lambda d: open(os.path.join(d, "ctlio_sim.yaml"), "w").write(
        "format: ctlio_sim\nversion: 2\nimu_from_lidar: [[[\n")))
    m.append(("dataset_yaml", "wrong_version",
              lambda d: edit_yaml(d, r"version: 2", "version: 99")))
    return m


def config_mutations(base_config):
    """(class, name, config text) — keys of data/sim_lio.yaml given bad values."""
    text = open(base_config).read()
    keys = re.findall(r"^\s+([a-z_]+):\s*([-0-9.e]+)\s*(?:#.*)?$", text, re.M)
    out = []
    for key, _ in keys[:40]:
        for bad in (".nan", "-1", "1e30"):
            new = re.sub(rf"^(\s+{key}:)\s*[-0-9.e]+", rf"\1 {bad}", text, count=1, flags=re.M)
            out.append(("config", f"{key}={bad}", new))
    return out


FLAG_MUTATIONS = [
    ("flags", "max_scans=-1", ["--max_scans=-1"]),
    ("flags", "play_rate=-1", ["--play_rate=-1"]),
    ("flags", "play_rate=nan", ["--play_rate=nan"]),
    ("flags", "frontend_threads=100000", ["--frontend_threads=100000"]),
    ("flags", "frontend_threads=0", ["--frontend_threads=0"]),
    ("flags", "map_voxel_size=0", ["--save_map", "--map_voxel_size=0"]),
    ("flags", "method=unknown", ["--method=foo"]),
    ("flags", "imu_accel_scale=nan", ["--imu_accel_scale=nan"]),
    ("flags", "max_imu_gap_error=-1", ["--max_imu_gap_error=-1"]),
]


def bag_mutations(rng, size, cls="bag"):
    out = []
    for k in range(8):
        cut = rng.randrange(13, size)
        out.append((cls, f"truncated_at_{cut}", ("truncate", cut)))
    for k in range(12):
        n = rng.choice((1, 4, 64))
        out.append((cls, f"byte_flips_{n}_{k}",
                    ("flip", [(rng.randrange(size), rng.randrange(256)) for _ in range(n)])))
    return out


def ros2_storage_file(folder):
    """The one storage file (.mcap or .db3) of a ROS 2 bag folder."""
    files = [f for f in os.listdir(folder) if f.endswith((".mcap", ".db3"))]
    assert len(files) == 1, (folder, files)
    return os.path.join(folder, files[0])


def ros2_mutations(rng, folder, cls):
    """Byte edits of the storage file (as for the ROS 1 bag) and of the folder around it."""
    out = bag_mutations(rng, os.path.getsize(ros2_storage_file(folder)), cls)
    out.append((cls, "metadata_missing", ("metadata", None)))
    out.append((cls, "metadata_garbage", ("metadata", "rosbag2_bagfile_information: [[[\n")))
    out.append((cls, "metadata_wrong_storage",
                ("metadata_sub", ("storage_identifier: mcap", "storage_identifier: sqlite3")
                 if cls == "ros2_mcap" else
                 ("storage_identifier: sqlite3", "storage_identifier: mcap"))))
    out.append((cls, "storage_file_missing", ("remove", None)))
    return out


def mutate_bytes(data, what):
    data = bytearray(data)
    if what[0] == "truncate":
        return bytes(data[:what[1]])
    for pos, val in what[1]:
        data[pos] = val
    return bytes(data)
