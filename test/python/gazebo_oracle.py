"""An independent reading of Gazebo worlds for the tests: SDF poses and Collada meshes with
xml.etree and numpy only (no SDFormat, no assimp, nothing of bvc3d).

Scope: what the AWS RoboMaker worlds and the tests' hand-made worlds use -- `<include>` of
`model://NAME` (the include's pose replaces the model's), inline and nested `<model>`s, links,
visuals and collisions with poses relative to their parent (no `relative_to`), box, cylinder,
sphere, plane and mesh geometry with `<scale>`. Collada: `<library_geometries>` meshes
(`<triangles>`, `<polylist>`, `<polygons>`), node transforms (`<matrix>`, `<translate>`, `<rotate>`,
`<scale>`), `<instance_node>`, `<unit meter>`; the coordinates are taken as z-up whatever
`<up_axis>` says, as Gazebo reads them.
"""

import os
import re
import xml.etree.ElementTree as ET

import numpy as np


def rpy_matrix(roll, pitch, yaw):
    """SDF's rotation: extrinsic X-Y-Z (roll about x, then pitch about y, then yaw about z)."""
    cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def pose_matrix(values):
    x, y, z, roll, pitch, yaw = (float(v) for v in values)
    m = np.eye(4)
    m[:3, :3] = rpy_matrix(roll, pitch, yaw)
    m[:3, 3] = (x, y, z)
    return m


def _local(tag):
    return tag.rsplit("}", 1)[-1]


def _child(elem, name):
    for c in elem:
        if _local(c.tag) == name:
            return c
    return None


def _children(elem, name):
    return [c for c in elem if _local(c.tag) == name]


def _pose_of(elem):
    p = _child(elem, "pose")
    if p is None or not (p.text or "").split():
        return None
    return pose_matrix(p.text.split())


def _floats(text):
    return np.array([float(v) for v in text.split()])


def axis_angle_matrix(axis, angle_deg):
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    t = np.radians(angle_deg)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(t) * k + (1 - np.cos(t)) * (k @ k)


class Collada:
    """The triangles of a Collada file, in meters, after its node transforms."""

    def __init__(self, path):
        self.root = ET.parse(path).getroot()
        self.ids = {}  # (tag, id) -> element: files reuse one id for a scene and its node
        for e in self.root.iter():
            if "id" in e.attrib:
                self.ids[(_local(e.tag), e.attrib["id"])] = e
        asset = _child(self.root, "asset")
        unit = _child(asset, "unit") if asset is not None else None
        self.meter = float(unit.attrib.get("meter", "1")) if unit is not None else 1.0

    def _ref(self, url, *tags):
        for tag in tags:
            if (tag, url.lstrip("#")) in self.ids:
                return self.ids[(tag, url.lstrip("#"))]
        raise KeyError(f"no {'/'.join(tags)} with id {url}")

    def _positions(self, mesh, source_url):
        e = self._ref(source_url, "vertices", "source")
        if _local(e.tag) == "vertices":
            for inp in _children(e, "input"):
                if inp.attrib["semantic"] == "POSITION":
                    return self._positions(mesh, inp.attrib["source"])
            raise ValueError("vertices without POSITION")
        arr = _child(e, "float_array")
        stride = 3
        tc = _child(e, "technique_common")
        if tc is not None and _child(tc, "accessor") is not None:
            stride = int(_child(tc, "accessor").attrib.get("stride", 3))
        return _floats(arr.text or "").reshape(-1, stride)[:, :3]

    def _mesh_triangles(self, geometry):
        mesh = _child(geometry, "mesh")
        if mesh is None:
            return np.zeros((0, 3, 3))
        out = []
        for prim in mesh:
            kind = _local(prim.tag)
            if kind not in ("triangles", "polylist", "polygons"):
                continue
            inputs = _children(prim, "input")
            n_off = max(int(i.attrib.get("offset", 0)) for i in inputs) + 1
            vin = [i for i in inputs if i.attrib["semantic"] == "VERTEX"][0]
            pos = self._positions(mesh, vin.attrib["source"])
            voff = int(vin.attrib.get("offset", 0))
            polys = []
            if kind == "polygons":
                for p in _children(prim, "p"):
                    idx = _floats(p.text or "").astype(int).reshape(-1, n_off)[:, voff]
                    polys.append(idx)
            else:
                p = _child(prim, "p")
                if p is None:
                    continue
                idx = _floats(p.text or "").astype(int).reshape(-1, n_off)[:, voff]
                if kind == "triangles":
                    polys = list(idx.reshape(-1, 3))
                else:
                    counts = _floats(_child(prim, "vcount").text).astype(int)
                    start = 0
                    for c in counts:
                        polys.append(idx[start : start + c])
                        start += c
            for poly in polys:
                for k in range(1, len(poly) - 1):  # a fan, as a convex polygon is triangulated
                    out.append(pos[[poly[0], poly[k], poly[k + 1]]])
        return np.array(out).reshape(-1, 3, 3)

    @staticmethod
    def _node_transform(node):
        m = np.eye(4)
        for t in node:
            kind = _local(t.tag)
            if kind == "matrix":
                m = m @ _floats(t.text).reshape(4, 4)
            elif kind == "translate":
                s = np.eye(4)
                s[:3, 3] = _floats(t.text)
                m = m @ s
            elif kind == "rotate":
                v = _floats(t.text)
                s = np.eye(4)
                s[:3, :3] = axis_angle_matrix(v[:3], v[3])
                m = m @ s
            elif kind == "scale":
                m = m @ np.diag(list(_floats(t.text)) + [1.0])
        return m

    def _node(self, node, parent, out):
        m = parent @ self._node_transform(node)
        for g in _children(node, "instance_geometry"):
            tri = self._mesh_triangles(self._ref(g.attrib["url"], "geometry"))
            if len(tri):
                h = np.concatenate([tri, np.ones(tri.shape[:2] + (1,))], axis=2)
                out.append((h @ m.T)[..., :3])
        for inst in _children(node, "instance_node"):
            self._node(self._ref(inst.attrib["url"], "node"), m, out)
        for child in _children(node, "node"):
            self._node(child, m, out)

    def triangles(self):
        scene = _child(_child(self.root, "scene"), "instance_visual_scene")
        vs = self._ref(scene.attrib["url"], "visual_scene")
        out = []
        for node in _children(vs, "node"):
            self._node(node, np.eye(4), out)
        tri = np.concatenate(out) if out else np.zeros((0, 3, 3))
        return tri * self.meter


class Geometry:
    """One `<visual>` or `<collision>`: its path, world pose and geometry element."""

    def __init__(self, path, pose, element, model_dir):
        self.path, self.pose, self.element, self.model_dir = path, pose, element, model_dir

    @property
    def kind(self):
        return _local(self.element[0].tag) if len(self.element) else None

    def mesh_file(self, models):
        uri = _child(_child(self.element, "mesh"), "uri").text.strip()
        if uri.startswith("model://"):
            name, rest = uri[len("model://") :].split("/", 1)
            return os.path.join(find_model(name, models), rest)
        return os.path.join(self.model_dir, uri)

    def mesh_scale(self):
        s = _child(_child(self.element, "mesh"), "scale")
        return _floats(s.text) if s is not None else np.ones(3)


def find_model(name, models):
    for folder in models:
        if os.path.isdir(os.path.join(folder, name)):
            return os.path.join(folder, name)
    return None


def model_file(folder):
    # Some model.config files are not well-formed XML (a bare '&' in a description): read the one tag.
    with open(os.path.join(folder, "model.config"), encoding="utf-8") as f:
        return os.path.join(folder, re.search(r"<sdf[^>]*>([^<]*)</sdf>", f.read()).group(1).strip())


BUILT_IN = ("sun", "ground_plane")


def _walk_model(model, pose, path, kind, models, model_dir, out, missing):
    for link in _children(model, "link"):
        lp = _pose_of(link)
        link_pose = pose @ (lp if lp is not None else np.eye(4))
        for g in _children(link, kind):
            gp = _pose_of(g)
            out.append(
                Geometry(
                    f"{path}/{link.attrib['name']}/{g.attrib['name']}",
                    link_pose @ (gp if gp is not None else np.eye(4)),
                    _child(g, "geometry"),
                    model_dir,
                )
            )
    for nested in _children(model, "model"):
        np_ = _pose_of(nested)
        _walk_model(
            nested,
            pose @ (np_ if np_ is not None else np.eye(4)),
            f"{path}/{nested.attrib['name']}",
            kind,
            models,
            model_dir,
            out,
            missing,
        )
    for inc in _children(model, "include"):
        _include(inc, pose, path, kind, models, out, missing)


def _include(inc, parent_pose, path, kind, models, out, missing):
    uri = _child(inc, "uri").text.strip()
    name = uri[len("model://") :]
    folder = find_model(name, models)
    if folder is None:
        if name not in BUILT_IN:
            missing.append(name)
        return
    m = ET.parse(model_file(folder)).getroot()
    m = _child(m, "model")
    ip = _pose_of(inc)
    own = _pose_of(m)
    pose = parent_pose @ (ip if ip is not None else (own if own is not None else np.eye(4)))
    n = _child(inc, "name")
    label = n.text.strip() if n is not None else m.attrib["name"]
    _walk_model(m, pose, f"{path}/{label}", kind, models, folder, out, missing)


def world_geometry(world_file, models, kind="visual"):
    """Every visual (or collision) of a world with its pose in the world frame, and the names of the
    included models that were not found (Gazebo's own sun and ground plane excepted)."""
    root = ET.parse(world_file).getroot()
    world = _child(root, "world")
    out, missing = [], []
    wname = world.attrib["name"]
    for inc in _children(world, "include"):
        _include(inc, np.eye(4), wname, kind, models, out, missing)
    for model in _children(world, "model"):
        mp = _pose_of(model)
        _walk_model(
            model,
            mp if mp is not None else np.eye(4),
            f"{wname}/{model.attrib['name']}",
            kind,
            models,
            os.path.dirname(world_file),
            out,
            missing,
        )
    return out, missing


def placed_mesh(geometry, models, cache=None):
    """A mesh geometry's triangles in the world frame: Collada read here, scaled, then posed."""
    f = geometry.mesh_file(models)
    if cache is not None and f in cache:
        tri = cache[f]
    else:
        tri = Collada(f).triangles()
        if cache is not None:
            cache[f] = tri
    tri = tri * geometry.mesh_scale()
    return tri @ geometry.pose[:3, :3].T + geometry.pose[:3, 3]
