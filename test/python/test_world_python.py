"""Worlds built in Python (issue 32, finding 7): World.from_dict and World.from_triangles, checked against
analytic ranges, and their errors naming the key."""
import numpy as np
import pytest

import bvc3d


def test_a_box_room_from_a_dict_gives_the_analytic_ranges():
    room = bvc3d.World.from_dict({"objects": [{"box": {"center": [0, 0, 1.25], "size": [8, 6, 2.5]}}],
                                  "walkable": {"rect": [-3.5, -2.5, 3.5, 2.5]}}, name="room")
    assert room.name == "room" and room.triangles.shape == (12, 3, 3)
    s = room.scan("horizontal", 0.5, 0.0, 0.0)
    r, az = s[:, 0], s[:, 1]
    # Horizontal beams from (0.5, 0) to the walls x = ±4, y = ±3 (hand geometry, not the ray caster's).
    with np.errstate(divide="ignore"):
        tx = np.where(np.cos(az) > 0, 3.5 / np.cos(az), -4.5 / np.cos(az))
        ty = np.abs(3.0 / np.sin(az))
    expected = np.minimum(np.where(tx > 0, tx, np.inf), ty)
    np.testing.assert_allclose(r, expected, rtol=1e-6)


FLOOR = [[[-5, -5, 0], [5, -5, 0], [5, 5, 0]], [[-5, -5, 0], [5, 5, 0], [-5, 5, 0]]]


def test_triangles_make_a_wall_at_the_right_distance():
    corners = np.array(FLOOR + [[[3, -5, 0], [3, 5, 0], [3, 5, 2]], [[3, -5, 0], [3, 5, 2], [3, -5, 2]]], float)
    wall = bvc3d.World.from_triangles(corners, walkable=(-4, -4, 2, 4))
    np.testing.assert_array_equal(np.sort(wall.triangles.reshape(-1, 3), axis=0),
                                  np.sort(corners.reshape(-1, 3), axis=0))
    s = wall.scan("horizontal", 0, 0, 0)
    np.testing.assert_allclose(s[:, 0], 3 / np.cos(s[:, 1]), rtol=1e-6)
    assert np.all(np.abs(np.tan(s[:, 1])) * 3 <= 5 + 1e-9)  # only the wall's 10 m width is hit


def test_a_polygon_walkable_region_and_a_start_region_are_kept():
    corners = np.array(FLOOR + [[[3, -5, 0], [3, 5, 0], [3, 5, 2]]], float)
    polygon = np.array([[-2, -2], [2, -2], [2, 2], [-2, 2]], float)
    w = bvc3d.World.from_triangles(corners, walkable=polygon, start=(-1, -1, 1, 1))
    np.testing.assert_array_equal(w.walkable, polygon)


@pytest.mark.parametrize("description,words", [
    ({"objects": [{"box": {"center": [0, 0, 1], "size": [1, -1, 1]}}], "walkable": {"rect": [-1, -1, 1, 1]}},
     ["objects[0].box.size", "> 0"]),
    ({"objects": [{"cube": {}}], "walkable": {"rect": [-1, -1, 1, 1]}}, ["objects[0]", "cube", "triangle"]),
    ({"objects": [{"box": {"center": [0, 0, float("nan")], "size": [1, 1, 1]}}]}, ["NaN"]),
    ({"objects": [{"box": {"center": [0, 0, 1], "size": [1, 1, 1], "colour": 1}}]}, ["colour"]),
])
def test_bad_descriptions_name_the_key(description, words):
    with pytest.raises(ValueError) as e:
        bvc3d.World.from_dict(description)
    for w in words:
        assert w in str(e.value)


@pytest.mark.parametrize("triangles,walkable,words", [
    (np.zeros((2, 3)), (-1, -1, 1, 1), ["(T, 3, 3)"]),
    (np.zeros((1, 3, 3)), (-1, -1, 1, 1), ["objects[0].triangle", "degenerate"]),
    (np.full((1, 3, 3), np.nan), (-1, -1, 1, 1), ["triangles[0]", "NaN"]),
    (np.array([[[3, -5, 0], [3, 5, 0], [3, 5, 2]]], float), (0, 1), ["walkable"]),
])
def test_bad_triangles_are_refused_naming_them(triangles, walkable, words):
    with pytest.raises(ValueError) as e:
        bvc3d.World.from_triangles(triangles, walkable=walkable)
    for w in words:
        assert w in str(e.value)
