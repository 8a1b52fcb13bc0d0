#!/usr/bin/env python3
"""Writes the corpus cases that are binary or made in bulk: broken meshes (each with the world file
that loads it) and broken recordings. The outputs are committed; rerun this after changing it:

    /usr/bin/python3 test/bad_inputs/make_cases.py
"""
import base64
import json
import pathlib
import struct

HERE = pathlib.Path(__file__).resolve().parent
MESHES = HERE / "meshes"
RECORDINGS = HERE / "recordings"

CUBE_V = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
CUBE_F = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4), (1, 2, 6), (1, 6, 5), (2, 3, 7), (2, 7, 6),
          (3, 0, 4), (3, 4, 7)]


def ply_header(fmt, nv, nf, extra=""):
    return (f"ply\nformat {fmt} 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\nproperty float z\n"
            f"element face {nf}\nproperty list uchar int vertex_indices\n{extra}end_header\n").encode()


def ply_binary(vertices=CUBE_V, faces=CUBE_F, nv=None, nf=None, big=False):
    e = ">" if big else "<"
    body = b"".join(struct.pack(e + "3f", *v) for v in vertices)
    body += b"".join(struct.pack(e + "B3i", 3, *f) for f in faces)
    fmt = "binary_big_endian" if big else "binary_little_endian"
    return ply_header(fmt, len(vertices) if nv is None else nv, len(faces) if nf is None else nf) + body


def ply_ascii(vertices=CUBE_V, faces=CUBE_F, nv=None, nf=None):
    body = "".join(f"{x} {y} {z}\n" for x, y, z in vertices) + "".join(f"3 {a} {b} {c}\n" for a, b, c in faces)
    return ply_header("ascii", len(vertices) if nv is None else nv, len(faces) if nf is None else nf) + body.encode()


def obj(vertices=CUBE_V, faces=CUBE_F, extra=""):
    return ("".join(f"v {x} {y} {z}\n" for x, y, z in vertices) +
            "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces) + extra).encode()


def stl_binary(faces=CUBE_F, count=None):
    body = b""
    for f in faces:
        body += struct.pack("<3f", 0, 0, 1) + b"".join(struct.pack("<3f", *CUBE_V[i]) for i in f) + b"\0\0"
    return b"binary stl".ljust(80, b" ") + struct.pack("<I", len(faces) if count is None else count) + body


def stl_ascii(faces=CUBE_F, end=True):
    s = "solid cube\n"
    for f in faces:
        s += "  facet normal 0 0 1\n    outer loop\n"
        s += "".join(f"      vertex {x} {y} {z}\n" for x, y, z in (CUBE_V[i] for i in f))
        s += "    endloop\n  endfacet\n"
    return (s + ("endsolid cube\n" if end else "")).encode()


def gltf(indices=(0, 1, 2, 1, 3, 2), count=4, buffer_len=None, uri="data"):
    pos = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 1)
    idx = struct.pack("<6H", *indices) + b"\0\0"
    buf = pos + idx
    doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
           "buffers": [{"uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode(),
                        "byteLength": len(buf) if buffer_len is None else buffer_len}],
           "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                           {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3",
                          "min": [0, 0, 0], "max": [1, 1, 1]},
                         {"bufferView": 1, "componentType": 5123, "count": len(indices), "type": "SCALAR"}]}
    return json.dumps(doc, indent=1).encode()


def glb(truncate=0):
    doc = json.loads(gltf())
    pos = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 1)
    buf = pos + struct.pack("<6H", 0, 1, 2, 1, 3, 2) + b"\0\0"
    doc["buffers"] = [{"byteLength": len(buf)}]
    j = json.dumps(doc).encode()
    j += b" " * ((4 - len(j) % 4) % 4)
    total = 12 + 8 + len(j) + 8 + len(buf)
    data = struct.pack("<4sII", b"glTF", 2, total) + struct.pack("<I4s", len(j), b"JSON") + j
    data += struct.pack("<I4s", len(buf), b"BIN\0") + buf
    return data[:len(data) - truncate] if truncate else data


# name: (bytes, what the message must say besides the file's name)
MESH_CASES = {
    "ply-ascii-claims-100.ply": (ply_header("ascii", 100, 50) + b"0 0 0\n1 0 1\n0 1 1\n", "is truncated"),
    "ply-ascii-short.ply": (ply_ascii()[:-20], "is truncated"),
    "ply-ascii-extra.ply": (ply_ascii() + b"3 0 1 2\n", "data after"),
    "ply-ascii-word.ply": (ply_ascii().replace(b"1 1 1\n", b"1 one 1\n"), "'one' is not a number"),
    "ply-ascii-index.ply": (ply_ascii(faces=CUBE_F[:-1] + [(3, 4, 8)]), "refers to vertex 8"),
    "ply-ascii-negative-index.ply": (ply_ascii(faces=CUBE_F[:-1] + [(3, -1, 7)]), "refers to vertex -1"),
    "ply-binary-truncated.ply": (ply_binary()[:-30], "is truncated"),
    "ply-binary-header-only.ply": (ply_header("binary_little_endian", 10 ** 12, 10 ** 12), "is truncated"),
    "ply-binary-index.ply": (ply_binary(faces=CUBE_F[:-1] + [(3, 4, 99)]), "refers to vertex 99"),
    "ply-binary-big-endian-index.ply": (ply_binary(faces=CUBE_F[:-1] + [(3, 4, 99)], big=True), "refers to vertex 99"),
    "ply-binary-extra.ply": (ply_binary() + b"\0" * 7, "data after"),
    "ply-list-length.ply": (ply_binary().replace(struct.pack("<B3i", 3, *CUBE_F[5]),
                                                 struct.pack("<B3i", 200, *CUBE_F[5])),
                            "refers to vertex 259"),
    "ply-unknown-format.ply": (ply_ascii().replace(b"format ascii", b"format utf8"), "unknown encoding"),
    "ply-unknown-type.ply": (ply_ascii().replace(b"property float y", b"property quad y"), "unknown property type"),
    "ply-no-end-header.ply": (b"ply\nformat ascii 1.0\nelement vertex 3\n", "not a PLY file"),
    "obj-face-index.obj": (obj(extra="f 1 2 9\n"), "refers to vertex 9"),
    "obj-face-backwards.obj": (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", "refers back past the first vertex"),
    "obj-truncated-vertex.obj": (obj() + b"v 1.0 2", "a vertex needs 3 numbers"),
    "obj-word.obj": (obj().replace(b"v 1 1 1", b"v 1 one 1"), "'one' is not a number"),
    "obj-two-corners.obj": (obj(extra="f 1 2\n"), "at least 3 vertices"),
    "obj-zero-index.obj": (obj(extra="f 0 1 2\n"), "not a valid vertex reference"),
    "obj-huge.obj": (b"v 0 0 0\nv 1 0 1e308\nv 0 1 0\nf 1 2 3\n", "not finite"),
    "obj-nan.obj": (b"v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n", "not finite"),
    "obj-texture-index.obj": (obj(extra="vt 0 0\nf 1/1 2/2 3/1\n"), "texture coordinate 2"),
    "obj-degenerate.obj": (b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "no non-degenerate triangles"),
    "stl-binary-truncated.stl": (stl_binary()[:-70], "not a consistent binary STL"),
    "stl-binary-count-small.stl": (stl_binary(count=2), "declares 2 triangles"),
    "stl-binary-count-huge.stl": (stl_binary(count=4000000000), "declares 4000000000 triangles"),
    "stl-ascii-no-endsolid.stl": (stl_ascii(end=False), "is truncated"),
    "stl-ascii-cut.stl": (stl_ascii()[:300], "is truncated"),
    "stl-ascii-word.stl": (stl_ascii().replace(b"vertex 1 1 1", b"vertex 1 x 1", 1), "'x' is not a finite number"),
    "stl-tiny.stl": (b"12345", "too short for a binary STL"),
    "gltf-buffer-short.gltf": (gltf(buffer_len=4000), "cannot be read as a mesh"),
    "gltf-accessor-count.gltf": (gltf(count=400), "cannot be read as a mesh"),
    "gltf-index-range.gltf": (gltf(indices=(0, 1, 2, 1, 3, 99)), "is inconsistent"),
    "gltf-truncated-json.gltf": (gltf()[:300], "cannot be read as a mesh"),
    "glb-truncated.glb": (glb(truncate=20), "cannot be read as a mesh"),
    "empty.obj": (b"", "cannot be read as a mesh"),
    "unknown-format.xyz": (b"0 0 0\n1 0 0\n", "cannot be read as a mesh"),
}

# Scans, pose files, scan lists and extrinsics: (bytes, command after `read-recording`, expectation).
def pcd(fields="x y z", size="4 4 4", type_="F F F", count="1 1 1", width=3, height=1, points=3, data="ascii",
        body=b"0 0 0\n1 1 1\n2 2 2\n", version="0.7"):
    head = (f"# .PCD v0.7\nVERSION {version}\nFIELDS {fields}\nSIZE {size}\nTYPE {type_}\nCOUNT {count}\n"
            f"WIDTH {width}\nHEIGHT {height}\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {points}\nDATA {data}\n").encode()
    return head + body


def cloud_ply(body, n=3, fmt="ascii"):
    return (f"ply\nformat {fmt} 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\n"
            "end_header\n").encode() + body


RECORDING_CASES = {
    "pcd-truncated-binary.pcd": (pcd(data="binary", body=struct.pack("<7f", *range(7))), "scan", "points"),
    "pcd-no-z.pcd": (pcd(fields="x y", size="4 4", type_="F F", count="1 1", body=b"0 0\n1 1\n2 2\n"), "scan", "z"),
    "pcd-width-height.pcd": (pcd(width=2, height=2, points=3), "scan", "WIDTH"),
    "pcd-word.pcd": (pcd(body=b"0 0 0\n1 one 1\n2 2 2\n"), "scan", "'one'"),
    "pcd-version.pcd": (pcd(version="0.5"), "scan", "version '0.5'"),
    "pcd-unknown-data.pcd": (pcd(data="zipped"), "scan", "DATA"),
    "pcd-compressed-bad.pcd": (pcd(data="binary_compressed", body=struct.pack("<II", 1000, 36) + b"xx"), "scan", ""),
    "pcd-x-int.pcd": (pcd(type_="I F F"), "scan", "x"),
    "pcd-huge-points.pcd": (pcd(width=10 ** 12, points=10 ** 12, data="binary", body=b""), "scan", ""),
    "ply-cloud-short.ply": (cloud_ply(b"0 0 0\n1 1 1\n", n=3), "scan", ""),
    "ply-cloud-binary-short.ply": (cloud_ply(struct.pack("<5f", *range(5)), n=2, fmt="binary_little_endian"),
                                   "scan", ""),
    "ply-cloud-no-vertex.ply": (b"ply\nformat ascii 1.0\nelement face 0\n"
                                b"property list uchar int vertex_indices\nend_header\n",
                                "scan", "vertex"),
    "kitti-odd-size.bin": (struct.pack("<5f", *range(5)), "scan", "16"),
    "kitti-empty.bin": (b"", "scan", "empty"),
    "unknown-extension.las": (b"LASF", "scan", "extension"),
    "poses-kitti-11.txt": (b"1 0 0 0 0 1 0 0 0 0 1\n", "poses kitti", "line 1"),
    "poses-kitti-not-rotation.txt": (b"2 0 0 0 0 1 0 0 0 0 1 0\n", "poses kitti", "line 1"),
    "poses-kitti-nan.txt": (b"1 0 0 nan 0 1 0 0 0 0 1 0\n", "poses kitti", "line 1"),
    "poses-tum-zero-quaternion.txt": (b"0.0 1 2 3 0 0 0 0\n", "poses tum", "line 1"),
    "poses-tum-word.txt": (b"0.0 1 2 three 0 0 0 1\n", "poses tum", "'three'"),
    "poses-matrix-last-row.txt": (b"1 0 0 0\n0 1 0 0\n0 0 1 0\n0 1 0 1\n", "poses matrix", "line 4"),
    "poses-matrix-three-rows.txt": (b"1 0 0 0\n0 1 0 0\n0 0 1 0\n", "poses matrix", ""),
    "poses-mixed.txt": (b"1 0 0 0 0 1 0 0 0 0 1 0\n0.0 1 2 3 0 0 0 1\n", "poses auto", "line 2"),
    "poses-empty.txt": (b"", "poses auto", ""),
    "poses-binary.txt": (bytes(range(256)), "poses auto", ""),
    "list-missing-scan.txt": (b"no-such-scan.pcd\n", "list", "line 1"),
    "list-mixed-times.txt": (b"../data/one.pcd 0.5\n../data/one.pcd\n", "list", "line 2"),
    "list-bad-time.txt": (b"../data/one.pcd soon\n", "list", "line 1"),
    "extrinsics-13.txt": (b"1 0 0 0 0 1 0 0 0 0 1 0 5\n", "extrinsics", "13"),
    "extrinsics-not-rotation.txt": (b"1 1 0 0 0 1 0 0 0 0 1 0\n", "extrinsics", ""),
    "extrinsics-last-row.txt": (b"1 0 0 0 0 1 0 0 0 0 1 0 0 0 1 1\n", "extrinsics", ""),
}


def main():
    MESHES.mkdir(exist_ok=True)
    RECORDINGS.mkdir(exist_ok=True)
    lines = ["# Made by ../make_cases.py. Each mesh is loaded by a world file of the same stem "
             "(FILE | COMMAND | EXPECT)."]
    for name, (data, expect) in MESH_CASES.items():
        (MESHES / name).write_bytes(data)
        world = name.rsplit(".", 1)[0] + ".world.yaml"
        (MESHES / world).write_text(f"# Loads {name}, a broken mesh (made by ../make_cases.py).\n"
                                    f"objects:\n  - cross_arena: {{}}\n  - mesh: {{file: {name}}}\n")
        lines.append(f"{world} | walk --world {{}} --hours 0.01 | objects[1].mesh.file; {name}; {expect}")
    (MESHES / "cases.txt").write_text("\n".join(lines) + "\n")
    lines = ["# Made by ../make_cases.py: read by the recording stage's readers (FILE | COMMAND | EXPECT)."]
    for name, (data, how, expect) in RECORDING_CASES.items():
        (RECORDINGS / name).write_bytes(data)
        lines.append(f"{name} | read-recording {how} {{}} | {expect}")
    (RECORDINGS / "cases.txt").write_text("\n".join(lines) + "\n")
    (HERE / "data" / "one.pcd").write_bytes(pcd())
    print(f"{len(MESH_CASES)} mesh cases, {len(RECORDING_CASES)} recording cases")


if __name__ == "__main__":
    main()
