#!/usr/bin/env python3
"""Writes the corpus of broken mesh files next to this script.

Each file is named `<case>.<kind>.<location>.<ext>`: `kind` is the `Error::kind()` slug the reader
must return, `location` is `line-N` (text formats), `byte-N` (binary formats) or `none` (errors
without a position, e.g. a count over the configured limit). The expected values are worked out
here, by hand and by struct arithmetic, not by running the reader. `core/tests/io_corpus.rs`
reads every file and checks both. Re-run after editing:  python3 core/tests/corpus/make_corpus.py
"""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
CASES = []


def case(name, kind, loc, ext, data):
    if isinstance(data, str):
        data = data.encode()
    CASES.append((f"{name}.{kind}.{loc}.{ext}", data))


TRI = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"

# ---- OBJ -------------------------------------------------------------------------------------
case("empty", "malformed-input", "byte-0", "obj", b"")
case("whitespace-only", "malformed-input", "byte-0", "obj", " \n\t\r\n")
case("nan-coordinate", "invalid-mesh", "line-2", "obj", "v 0 0 0\nv nan 1 2\nv 0 1 0\nf 1 2 3\n")
case("inf-coordinate", "invalid-mesh", "line-3", "obj", "v 0 0 0\nv 1 0 0\nv 1e999 1 0\nf 1 2 3\n")
case("index-out-of-range", "invalid-mesh", "line-5", "obj", TRI + "f 1 2 3\nf 1 2 9\n")
case("index-zero", "invalid-mesh", "line-4", "obj", TRI + "f 0 1 2\n")
case("relative-index-before-start", "invalid-mesh", "line-4", "obj", TRI + "f -1 -2 -4\n")
case("uv-index-out-of-range", "invalid-mesh", "line-5", "obj", TRI + "vt 0 0\nf 1/1 2/1 3/2\n")
case("face-two-vertices", "malformed-input", "line-4", "obj", TRI + "f 1 2\n")
case("bad-number", "malformed-input", "line-2", "obj", "v 0 0 0\nv 1 x 0\n")
case("truncated-mid-face", "malformed-input", "line-4", "obj", TRI + "f 1 2")
case("truncated-mid-vertex", "malformed-input", "line-3", "obj", "v 0 0 0\nv 1 0 0\nv 0 1")
case("no-vertices", "malformed-input", "line-2", "obj", "# only a group\ng lonely\n")
# A text start, then binary: the NUL-bearing line is refused rather than skipped as a keyword.
case("binary-garbage", "malformed-input", "line-2", "obj", b"v 0 0 0\n\x00\x9f\x12\xff\xfe junk\n")

# ---- PLY -------------------------------------------------------------------------------------
def ply_header(fmt, nv, nf, vprops="property float x\nproperty float y\nproperty float z\n",
               fprops="property list uchar int vertex_indices\n"):
    return (f"ply\nformat {fmt} 1.0\nelement vertex {nv}\n{vprops}"
            f"element face {nf}\n{fprops}end_header\n").encode()


# 4e9 vertices is over the default 50M limit: refused before anything is read or allocated.
case("huge-vertex-count", "too-large", "none", "ply",
     ply_header("ascii", 4000000000, 1) + b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
# 40M vertices is under the limit but 40M x 12 bytes cannot be in a 51-byte body: refused at the
# body's first byte without allocating 40M vertices.
h = ply_header("binary_little_endian", 40000000, 1)
body = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<B3i", 3, 0, 1, 2)
case("lying-binary-counts", "malformed-input", f"byte-{len(h)}", "ply", h + body)
# The same lie in ascii is found where the data runs out: the header has 9 lines, data 4 more.
h = ply_header("ascii", 40000000, 1)
case("lying-ascii-counts", "malformed-input", "line-13", "ply", h + b"0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
# Honest header, body cut inside the face's second index (3 x 12 vertex bytes, count byte, one
# int, 2 of 4 bytes): the face's count promises more than is left, reported at the count byte.
h = ply_header("binary_little_endian", 3, 1)
full = h + body
cut = len(h) + 36 + 1 + 4 + 2
case("truncated-binary", "malformed-input", f"byte-{len(h) + 36}", "ply", full[:cut])
# Cut inside the vertices: the header's counts need more bytes than the body has, refused up front.
case("truncated-in-vertices", "malformed-input", f"byte-{len(h)}", "ply", full[:len(h) + 20])
case("index-out-of-range", "invalid-mesh", "line-13", "ply",
     ply_header("ascii", 3, 1) + b"0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n")
case("face-two-vertices", "malformed-input", "line-13", "ply",
     ply_header("ascii", 3, 1) + b"0 0 0\n1 0 0\n0 1 0\n2 0 1\n")
case("nan-coordinate-ascii", "invalid-mesh", "line-11", "ply",
     ply_header("ascii", 3, 1) + b"0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n")
# NaN in the second vertex of a binary body: located at that vertex's first byte.
nan_body = struct.pack("<9f", 0, 0, 0, 1, float("nan"), 0, 0, 1, 0) + struct.pack("<B3i", 3, 0, 1, 2)
h = ply_header("binary_little_endian", 3, 1)
case("nan-coordinate-binary", "invalid-mesh", f"byte-{len(h) + 12}", "ply", h + nan_body)
h = ply_header("binary_big_endian", 3, 1)
be = struct.pack(">9f", 0, 0, 0, 1, 0, 0, 0, float("inf"), 0) + struct.pack(">B3i", 3, 0, 1, 2)
case("inf-coordinate-big-endian", "invalid-mesh", f"byte-{len(h) + 24}", "ply", h + be)
# Found by the CLI fuzz campaign: NaN/inf in a normal or a texture coordinate was read, and
# `convert` then wrote an OBJ whose `vn` our own OBJ reader refuses. Located at the vertex.
h = ply_header("binary_little_endian", 3, 1, vprops="property float x\nproperty float y\nproperty float z\n"
               "property float nx\nproperty float ny\nproperty float nz\n")
nb = struct.pack("<18f", 0, 0, 0, 0, 0, 1, 1, 0, 0, 0, float("nan"), 1, 0, 1, 0, 0, 0, 1) + struct.pack("<B3i", 3, 0, 1, 2)
case("nan-normal-binary", "invalid-mesh", f"byte-{len(h) + 24}", "ply", h + nb)
case("inf-texture-coordinate-ascii", "invalid-mesh", "line-13", "ply",
     ply_header("ascii", 3, 1, vprops="property float x\nproperty float y\nproperty float z\n"
                "property float s\nproperty float t\n") + b"0 0 0 0 0\n1 0 0 inf 0\n0 1 0 0 1\n3 0 1 2\n")
# A list count of 255 on a 3-vertex face: the data ends before 255 ints. Located at the count byte.
h = ply_header("binary_little_endian", 3, 1)
case("list-count-beyond-data", "malformed-input", f"byte-{len(h) + 36}", "ply",
     h + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<B3i", 255, 0, 1, 2))
# A signed list count of -1.
h = ply_header("binary_little_endian", 3, 1, fprops="property list char int vertex_indices\n")
case("negative-list-count", "malformed-input", f"byte-{len(h) + 36}", "ply",
     h + struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<b3i", -1, 0, 1, 2))
case("no-end-header", "malformed-input", "line-6", "ply",
     b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n")
case("unknown-format", "malformed-input", "line-2", "ply", b"ply\nformat binary_middle_endian 1.0\nend_header\n")
case("vertex-without-z", "malformed-input", "line-3", "ply",
     b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n")
case("empty", "malformed-input", "byte-0", "ply", b"")

# ---- STL -------------------------------------------------------------------------------------
def stl_binary(tris, count=None, header=b"binary"):
    out = header.ljust(80, b" ") + struct.pack("<I", len(tris) if count is None else count)
    for t in tris:
        out += struct.pack("<3f", 0, 0, 1)
        for v in t:
            out += struct.pack("<3f", *v)
        out += b"\0\0"
    return out


T1 = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
T2 = [(0, 0, 0), (0, 1, 0), (0, 0, 1)]
good = stl_binary([T1, T2, T1])
# A truncated binary file no longer has 84 + 50n bytes; the header count is reported at byte 80.
case("truncated-binary", "malformed-input", "byte-80", "stl", good[:-10])
case("lying-count", "malformed-input", "byte-80", "stl", stl_binary([T1, T2], count=1000))
case("huge-count", "too-large", "none", "stl", stl_binary([T1, T2], count=4000000000))
# The header says "solid" (as many exporters' do) but the size says binary; NaN in triangle 1,
# vertex 2, x: 84 + 50 + 12 (normal) + 12 (vertex 1) bytes in.
case("nan-binary-solid-header", "invalid-mesh", f"byte-{84 + 50 + 24}", "stl",
     stl_binary([T1, [(0, 0, 0), (float("nan"), 1, 0), (0, 0, 1)]], header=b"solid looks like text"))
case("too-short", "malformed-input", "byte-40", "stl", bytes(range(40)))
ASCII_HEAD = "solid t\n facet normal 0 0 1\n  outer loop\n"
case("ascii-truncated", "malformed-input", "line-5", "stl",
     ASCII_HEAD + "   vertex 0 0 0\n   vertex 1 0 0\n")
case("ascii-nan", "invalid-mesh", "line-5", "stl",
     ASCII_HEAD + "   vertex 0 0 0\n   vertex 1 inf 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid t\n")
case("ascii-two-vertex-facet", "malformed-input", "line-7", "stl",
     ASCII_HEAD + "   vertex 0 0 0\n   vertex 1 0 0\n  endloop\n endfacet\nendsolid t\n")
case("ascii-bad-number", "malformed-input", "line-4", "stl",
     ASCII_HEAD + "   vertex 0 zero 0\n")

# ---- OFF -------------------------------------------------------------------------------------
case("lying-counts", "malformed-input", "line-5", "off", "OFF\n40000000 1 0\n0 0 0\n1 0 0\n0 1 0\n")
case("huge-count", "too-large", "none", "off", "OFF\n4000000000 1 0\n0 0 0\n")
case("index-out-of-range", "invalid-mesh", "line-6", "off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n")
case("negative-index", "invalid-mesh", "line-6", "off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n")
case("nan", "invalid-mesh", "line-4", "off", "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n")
case("face-two-vertices", "malformed-input", "line-6", "off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n")
case("missing-counts", "malformed-input", "line-2", "off", "OFF\n# nothing else\n")
case("truncated-face", "malformed-input", "line-6", "off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1")

# ---- no format at all ---------------------------------------------------------------------------
case("random-bytes", "unsupported-format", "none", "bin", bytes((i * 197 + 13) % 256 for i in range(300)))


def main():
    for f in os.listdir(HERE):
        if f.count(".") >= 3 and not f.endswith(".py"):
            os.remove(os.path.join(HERE, f))
    for name, data in CASES:
        with open(os.path.join(HERE, name), "wb") as fh:
            fh.write(data)
    print(f"wrote {len(CASES)} files to {HERE}")


if __name__ == "__main__":
    main()
