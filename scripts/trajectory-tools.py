#!/usr/bin/env python3
"""Two inputs of `arview eval` made from a tracked run and a map (docs/tracker.md, "The One Euro
filter's beta on real footage").

usage: trajectory-tools.py smoothed <trajectory.txt> <stats.json> <out.txt>
       trajectory-tools.py look-at <keyframes.txt>

smoothed: the raw trajectory `arview track --out` (or replay's `--trajectory`) wrote, each pose's
  centre replaced by the One Euro `smoothed_center` of the same frame in that run's `--stats`:
  the camera the smoothing gives (the pose `arview eval --smoothed` judges for the jitter), so
  that `arview eval` scores its centre error and, with `--points`, its registration in pixels.
look-at: the least-squares point nearest to every camera's optical axis (TUM, camera-to-world,
  OpenCV axes: the optical axis is the camera's +z), in the trajectory's frame, as a `--points`
  file: on a scene photographed from around it (templeRing's temple, phone-fox's fox head) the
  object the photos are of, where a character would stand.
"""
import json
import sys


def read_tum(path):
    """[(timestamp text, [tx, ty, tz], [qx, qy, qz, qw])] of a TUM file."""
    poses = []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            fields = line.split()
            if not fields or fields[0].startswith('#'):
                continue
            if len(fields) != 8:
                sys.exit(f"{path}:{number}: expected 'timestamp tx ty tz qx qy qz qw', got {len(fields)} fields")
            values = [float(v) for v in fields[1:]]
            poses.append((fields[0], values[:3], values[3:]))
    return poses


def smoothed(trajectory_path, stats_path, out_path):
    rotations = {round(float(stamp), 6): (stamp, q) for stamp, _, q in read_tum(trajectory_path)}
    try:
        with open(stats_path) as f:
            frames = json.load(f)["frames"]
    except (OSError, ValueError, KeyError) as e:
        sys.exit(f"{stats_path}: not a stats.json of arview track or replay: {e}")
    lines = []
    for frame in frames:
        if "smoothed_center" not in frame:
            continue  # a lost frame: no pose
        key = round(float(frame["timestamp"]), 6)
        if key not in rotations:
            sys.exit(f"{stats_path}: the frame at {frame['timestamp']} s has no pose in {trajectory_path}")
        stamp, q = rotations[key]
        c = frame["smoothed_center"]
        lines.append(" ".join([stamp] + [f"{v:.17g}" for v in list(c) + q]))
    if not lines:
        sys.exit(f"{stats_path}: no frame has a smoothed_center")
    with open(out_path, "w") as f:
        f.write(f"# the smoothed centres of {stats_path} with the raw rotations of {trajectory_path}\n")
        f.write("# timestamp tx ty tz qx qy qz qw (camera-to-world)\n")
        f.write("\n".join(lines) + "\n")


def determinant(m):
    return (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]))


def solve(a, b):
    """x with a x = b (3x3, Cramer's rule); None when a is near singular."""
    d = determinant(a)
    scale = max(abs(v) for row in a for v in row)
    if abs(d) < 1e-9 * scale ** 3:
        return None
    return [determinant([[b[i] if j == k else a[i][j] for j in range(3)] for i in range(3)]) / d for k in range(3)]


def look_at(keyframes_path):
    poses = read_tum(keyframes_path)
    if len(poses) < 2:
        sys.exit(f"{keyframes_path}: {len(poses)} poses, at least 2 are needed")
    # minimise sum |(I - d d^T)(p - c)|^2: sum (I - d d^T) p = sum (I - d d^T) c
    a = [[0.0] * 3 for _ in range(3)]
    b = [0.0] * 3
    for _, c, (x, y, z, w) in poses:
        d = [2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)]  # the rotation's third column
        norm = sum(v * v for v in d) ** 0.5
        d = [v / norm for v in d]
        for i in range(3):
            for j in range(3):
                m = (1.0 if i == j else 0.0) - d[i] * d[j]
                a[i][j] += m
                b[i] += m * c[j]
    p = solve(a, b)
    if p is None:
        sys.exit(f"{keyframes_path}: the optical axes are parallel: no point they all look at")
    print(f"# the point nearest to the optical axes of {keyframes_path}")
    print(f"{p[0]:.9g} {p[1]:.9g} {p[2]:.9g}")


def main():
    usage = __doc__.split('\n\n')[1]
    if len(sys.argv) == 5 and sys.argv[1] == "smoothed":
        smoothed(*sys.argv[2:])
    elif len(sys.argv) == 3 and sys.argv[1] == "look-at":
        look_at(sys.argv[2])
    else:
        sys.exit(usage)


if __name__ == "__main__":
    main()
