"""HeadDirectionCells and GridCells against a numpy transcription of their equations, and grid spacing and
orientation recovered from a simulated rate map's autocorrelogram (docs/model-reference.md#grid-cells)."""
import numpy as np

import bvc3d


def test_head_direction_cells_are_cosines_of_the_heading():
    h = np.array([0.0, 0.3, -2.0, 7.0])
    want = np.cos(h[:, None] - 2 * np.pi * np.arange(8)[None, :] / 8)
    np.testing.assert_allclose(bvc3d.HeadDirectionCells(n=8).rates(h), want, atol=1e-12)


def test_flying_cells_are_the_dodecahedrons_vertices():
    # The face normals of the icosahedron with vertices (0, ±1, ±φ) (and cyclic) are the vertices of its dual
    # dodecahedron: (±1, ±1, ±1) and (0, ±φ, ±1/φ) (and cyclic).
    p = (1 + 5 ** 0.5) / 2
    v = [(a, b, c) for a in (-1, 1) for b in (-1, 1) for c in (-1, 1)]
    for a in (-p, p):
        for b in (-1 / p, 1 / p):
            v += [(0, a, b), (a, b, 0), (b, 0, a)]
    v = np.array(v) / np.linalg.norm(v, axis=1)[:, None]
    cells = bvc3d.HeadDirectionCells(space="spherical")
    u = cells.preferred
    assert np.abs(u @ v.T).max(axis=1).min() > 1 - 1e-12
    w = np.array([[1.0, 2.0, 3.0], [0.0, 0.0, -1.0]])
    np.testing.assert_allclose(cells.rates(w), (w / np.linalg.norm(w, axis=1)[:, None]) @ u.T, atol=1e-12)


def grid_rates(xy, spacing, orientations, phases):
    d = xy[:, None, :] - phases[None, :, :]
    c, s = np.cos(orientations), np.sin(orientations)
    rx, ry = c * d[..., 0] + s * d[..., 1], -s * d[..., 0] + c * d[..., 1]
    f, h = 2 * np.pi / spacing, 3 ** 0.5 / 2
    z = (np.cos(f * rx) + np.cos(f * (rx / 2 + h * ry)) + np.cos(f * (rx / 2 - h * ry))) / 3
    return np.clip((((z + 0.5) / 1.5) ** (2 / 3) - 0.7) / 0.3, 0, 1)


def test_grid_cells_follow_the_three_cosines():
    cells = bvc3d.GridCells(spacing=5.5, orientation=0.2, n=24, seed=3)
    np.testing.assert_allclose(cells.orientations, 0.2 + np.arange(24) % 8 * np.pi / 4, atol=1e-12)
    xy = np.random.default_rng(0).uniform(-10, 10, (200, 2))
    np.testing.assert_allclose(cells.rates(xy), grid_rates(xy, 5.5, cells.orientations, cells.phases), atol=1e-12)


def test_spacing_and_orientation_from_the_autocorrelogram():
    for spacing, orientation in [(4.0, 0.0), (7.0, 0.35)]:
        cells = bvc3d.GridCells(spacing=spacing, orientation=orientation, n=1, n_orientations=1, seed=1)
        bin_size, half = 0.1, 20.0
        g = np.arange(-half, half, bin_size) + bin_size / 2
        X, Y = np.meshgrid(g, g, indexing="xy")
        m = cells.rates(np.column_stack([X.ravel(), Y.ravel()]))[:, 0].reshape(X.shape)
        m = m - m.mean()
        F = np.fft.fft2(m, s=(2 * m.shape[0], 2 * m.shape[1]))
        ac = np.fft.fftshift(np.real(np.fft.ifft2(F * np.conj(F))))
        c = np.array(ac.shape) // 2
        iy, ix = np.indices(ac.shape)
        r = np.hypot(ix - c[1], iy - c[0]) * bin_size
        # Local maxima in a 5-bin neighbourhood, the six nearest the centre (not it).
        from numpy.lib.stride_tricks import sliding_window_view
        win = sliding_window_view(np.pad(ac, 2, constant_values=-np.inf), (5, 5)).max(axis=(2, 3))
        peaks = np.argwhere((ac == win) & (r > 1.0) & (r < 2 * spacing))
        d = r[peaks[:, 0], peaks[:, 1]]
        six = peaks[np.argsort(d)[:6]]
        dist = r[six[:, 0], six[:, 1]]
        np.testing.assert_allclose(dist, 2 * spacing / 3 ** 0.5, rtol=0.03)
        angles = np.arctan2((six[:, 0] - c[0]) * bin_size, (six[:, 1] - c[1]) * bin_size)
        want = (orientation + np.pi / 6) % (np.pi / 3)
        err = (angles - want + np.pi / 6) % (np.pi / 3) - np.pi / 6
        assert np.abs(err).max() < np.radians(2.5)
