"""KITTI-BEV images as a bvc3d recording (docs/place-recognition.md#kitti-bev).

The data set's README fixes how a pixel becomes a point: image SS/imgs/NNNNNN.png is 151 x 151 pixels of
0.4 m centred on the sensor, pixel (row, col) covering the sensor-frame square whose lower corner is
x = (75 - row) * 0.4, y = (75 - col) * 0.4 (x forward is up, y left is left); SS/pose.txt holds each scan's
world-from-LiDAR [R | t] (KITTI's 12 numbers a line). Every non-zero pixel becomes one point at its centre.

Its height is a choice (the images keep only a count of occupied 0.4 m voxels per column, scaled so that
each image's maximum is 255, in ten levels): `flat` puts every point at z = 0, the sensor's height (what
a 2-D model's horizontal slice reads); `heights` puts it at the top of a column of `level` voxels standing
on the road, z = -1.73 m + 0.4 m * level with level = round(value / 25.5) in 1..10 (1.73 m: KITTI's
LiDAR above the road), what Scan Context's largest-z bins read.

The recording: NNNNNN.bin (KITTI's float32 x, y, z, intensity; intensity 0), poses.txt (the pose file as
it is), scans.txt (the scan list with times 0.1 s apart: KITTI's LiDAR turns at 10 Hz).
"""
import pathlib

import numpy as np

PIXEL = 0.4
CENTRE = 75
SENSOR_HEIGHT = 1.73
SCAN_PERIOD = 0.1


def read_image(path):
    """The image's 8-bit values (0-255) as integers."""
    import matplotlib.image
    a = matplotlib.image.imread(str(path))
    if a.dtype != np.uint8:
        a = np.round(a * 255)
    return a.astype(np.int64)


def image_points(values, heights):
    """The points of one image: (N, 3) in the sensor frame, one per non-zero pixel, row-major order."""
    row, col = np.nonzero(values)
    x = (CENTRE - row) * PIXEL + PIXEL / 2
    y = (CENTRE - col) * PIXEL + PIXEL / 2
    if heights:
        z = -SENSOR_HEIGHT + PIXEL * np.clip(np.round(values[row, col] / 25.5), 1, 10)
    else:
        z = np.zeros(len(row))
    return np.column_stack([x, y, z])


def read_poses(sequence):
    """(n, 4, 4) world-from-LiDAR transforms of pose.txt."""
    m = np.loadtxt(pathlib.Path(sequence) / "pose.txt").reshape(-1, 3, 4)
    out = np.zeros((len(m), 4, 4))
    out[:, :3] = m
    out[:, 3, 3] = 1
    return out


def convert(sequence, out, heights=False, scans=None):
    """Writes sequence SS (its folder) as a recording into `out` (created): every scan, or the indices
    `scans`. Returns the number of scans written."""
    sequence, out = pathlib.Path(sequence), pathlib.Path(out)
    lines = (sequence / "pose.txt").read_text().splitlines()
    indices = range(len(lines)) if scans is None else list(scans)
    out.mkdir(parents=True, exist_ok=True)
    listing = []
    for k, i in enumerate(indices):
        p = image_points(read_image(sequence / "imgs" / f"{i:06d}.png"), heights)
        data = np.zeros((len(p), 4), dtype="<f4")
        data[:, :3] = p
        name = f"{i:06d}.bin"
        data.tofile(out / name)
        listing.append(f"{name} {i * SCAN_PERIOD:.1f}")
    (out / "scans.txt").write_text("\n".join(listing) + "\n")
    (out / "poses.txt").write_text("\n".join(lines[i] for i in indices) + "\n")
    return len(listing)
