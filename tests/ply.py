# SPDX-License-Identifier: Apache-2.0
"""A reader of the binary PLY meshes sweepers-cli writes, for the tests: independent of
the project's own reader, and strict about what it expects."""
import struct


def read_ply(path):
    """The vertices (x y z of each) and triangles of a binary little-endian PLY whose vertices
    are float properties, x y z first, and whose faces are uchar-counted int lists."""
    data = open(path, "rb").read()
    header, body = data.split(b"end_header\n", 1)
    lines = header.decode().splitlines()
    assert "format binary_little_endian 1.0" in lines, lines[:3]
    start = next(i for i, l in enumerate(lines) if l.startswith("element vertex"))
    count = int(lines[start].split()[2])
    props = 0
    for l in lines[start + 1:]:
        if not l.startswith("property"):
            break
        assert l.split()[1] == "float", l
        props += 1
    face_line = next(l for l in lines if l.startswith("element face"))
    faces = int(face_line.split()[2])
    kinds = lines[lines.index(face_line) + 1].split()
    assert kinds[:3] == ["property", "list", "uchar"] and kinds[3] in ("int", "uint"), kinds
    vertices = [struct.unpack_from("<3f", body, i * 4 * props) for i in range(count)]
    at, triangles = count * 4 * props, []
    for _ in range(faces):
        assert body[at] == 3, "not a triangle"
        triangles.append(struct.unpack_from("<3i", body, at + 1))
        at += 13
    assert at == len(body), (at, len(body))
    return vertices, triangles
