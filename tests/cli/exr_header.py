"""The header of an OpenEXR file as lines "name type value" (string, int, double,
chromaticities, and the channel list as "channels chlist A,B,G,R"; other types "-"):
python3 exr_header.py FILE.exr. For the CLI tests that check what atmos writes."""
import struct
import sys

b = open(sys.argv[1], "rb").read()
assert b[:4] == b"\x76\x2f\x31\x01", "not an EXR"
i = 8
while b[i] != 0:
    j = b.index(b"\0", i); name = b[i:j].decode()
    k = b.index(b"\0", j + 1); typ = b[j + 1:k].decode()
    n = struct.unpack("<i", b[k + 1:k + 5])[0]; v = b[k + 5:k + 5 + n]; i = k + 5 + n
    if typ == "string": v = v.decode()
    elif typ == "int": v = struct.unpack("<i", v)[0]
    elif typ == "double": v = repr(struct.unpack("<d", v)[0])
    elif typ == "chromaticities": v = ",".join("%.4f" % x for x in struct.unpack("<8f", v))
    elif typ == "chlist":
        names, p = [], 0
        while v[p] != 0:
            e = v.index(b"\0", p); names.append(v[p:e].decode()); p = e + 1 + 16
        v = ",".join(names)
    else: v = "-"
    print(name, typ, v)
