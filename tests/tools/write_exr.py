#!/usr/bin/env python3
"""Writes a small uncompressed scanline OpenEXR file, independently of atmos's writer,
so that tests can give `atmos compare` channel sets and types atmos never writes.

    write_exr.py OUT WIDTH HEIGHT NAME:TYPE:VALUES [NAME:TYPE:VALUES ...]

TYPE is uint, half or float; VALUES is one number (every pixel) or WIDTH*HEIGHT numbers
separated by commas, rows top first. Channels may be given in any order: the file lists
them sorted by name, as the format requires.
"""
import struct
import sys


def attr(name, type_name, payload):
    return name.encode() + b"\0" + type_name.encode() + b"\0" + struct.pack("<i", len(payload)) + payload


def main(argv):
    out, w, h = argv[1], int(argv[2]), int(argv[3])
    types = {"uint": (0, "<I", 4), "half": (1, "<e", 2), "float": (2, "<f", 4)}
    chans = []
    for spec in argv[4:]:
        name, type_name, values = spec.split(":", 2)
        vals = [float(v) for v in values.split(",")]
        if len(vals) == 1:
            vals = vals * (w * h)
        if len(vals) != w * h:
            sys.exit("%s: %d values for %d pixels" % (name, len(vals), w * h))
        chans.append((name, types[type_name], vals))
    chans.sort(key=lambda c: c[0].encode())
    chlist = b"".join(c[0].encode() + b"\0" + struct.pack("<iB3xii", c[1][0], 0, 1, 1) for c in chans) + b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = (b"\x76\x2f\x31\x01" + struct.pack("<i", 2) + attr("channels", "chlist", chlist) +
              attr("compression", "compression", b"\0") + attr("dataWindow", "box2i", box) +
              attr("displayWindow", "box2i", box) + attr("lineOrder", "lineOrder", b"\0") +
              attr("pixelAspectRatio", "float", struct.pack("<f", 1.0)) +
              attr("screenWindowCenter", "v2f", struct.pack("<ff", 0, 0)) +
              attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    lines = []
    for y in range(h):
        data = b""
        for _name, (_code, fmt, _size), vals in chans:
            conv = int if fmt == "<I" else float
            data += b"".join(struct.pack(fmt, conv(v)) for v in vals[y * w:(y + 1) * w])
        lines.append(struct.pack("<ii", y, len(data)) + data)
    offset = len(header) + 8 * h
    table = b""
    for line in lines:
        table += struct.pack("<Q", offset)
        offset += len(line)
    with open(out, "wb") as f:
        f.write(header + table + b"".join(lines))


if __name__ == "__main__":
    main(sys.argv)
