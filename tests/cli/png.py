"""8-bit RGB/RGBA PNG images for the tests, read independently of the library (zlib and the
five scanline filters of the PNG specification, section 9).

  png.read(path)        w, h and the rows of display values (each a list of [r, g, b])
  png.mean(path)        the mean of the R, G, B values over the image (0..255)
  png.white(path)       the share of pixels whose three values are all 250 or more
"""
import struct
import zlib


def read(path):
    b = open(path, "rb").read()
    w, h, depth, ctype = struct.unpack(">IIBB", b[16:26])
    assert depth == 8 and ctype in (2, 6), "%s: not an 8-bit RGB(A) PNG" % path
    i, data = 8, b""
    while i < len(b):
        n = struct.unpack(">I", b[i:i + 4])[0]
        if b[i + 4:i + 8] == b"IDAT":
            data += b[i + 8:i + 8 + n]
        i += 12 + n
    raw, bpp = zlib.decompress(data), 3 if ctype == 2 else 4
    stride, prev, p, rows = w * bpp, bytearray(w * bpp), 0, []
    for _ in range(h):
        f, line = raw[p], bytearray(raw[p + 1:p + 1 + stride])
        p += 1 + stride
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            c = prev[x - bpp] if x >= bpp else 0
            up = prev[x]
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + up) & 255
            elif f == 3:
                line[x] = (line[x] + (a + up) // 2) & 255
            elif f == 4:
                pa, pb, pc = abs(up - c), abs(a - c), abs(a + up - 2 * c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else up if pb <= pc else c)) & 255
        prev = line
        rows.append([list(line[x * bpp:x * bpp + 3]) for x in range(w)])
    return w, h, rows


def mean(path):
    w, h, rows = read(path)
    return sum(sum(px) for row in rows for px in row) / (3.0 * w * h)


def white(path):
    w, h, rows = read(path)
    return sum(1 for row in rows for px in row if min(px) >= 250) / float(w * h)
