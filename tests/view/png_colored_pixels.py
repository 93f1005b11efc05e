#!/usr/bin/python3
"""Counts the colored pixels of a PNG screenshot: png_colored_pixels.py FILE [MIN_FRACTION]

A pixel is colored when its channels differ by at least 24 (text, borders and the background
are gray or white; the drawn meshes and boxes are not). Prints the count and the fraction;
exits 1 when the fraction is below MIN_FRACTION. Pure Python (zlib): PIL is not installed.
"""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG")
    pos, idat, header = 8, [], None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        chunk = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", chunk)
        elif kind == b"IDAT":
            idat.append(chunk)
    width, height, depth, color, _, _, interlace = header
    if depth != 8 or color not in (2, 6) or interlace:
        raise ValueError(f"{path}: only 8-bit RGB/RGBA non-interlaced PNGs (got depth {depth}, color {color})")
    channels = 3 if color == 2 else 4
    raw = zlib.decompress(b"".join(idat))
    stride = width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        kind, line = raw[start], bytearray(raw[start + 1:start + 1 + stride])
        if kind == 1:
            for i in range(channels, stride):
                line[i] = (line[i] + line[i - channels]) & 255
        elif kind == 2:
            line = bytearray((a + b) & 255 for a, b in zip(line, previous))
        elif kind == 3:
            for i in range(stride):
                left = line[i - channels] if i >= channels else 0
                line[i] = (line[i] + ((left + previous[i]) >> 1)) & 255
        elif kind == 4:
            for i in range(stride):
                a = line[i - channels] if i >= channels else 0
                b, c = previous[i], previous[i - channels] if i >= channels else 0
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        previous = line
    return width, height, channels, rows


def main():
    path = sys.argv[1]
    minimum = float(sys.argv[2]) if len(sys.argv) > 2 else 0.0
    width, height, channels, rows = read_png(path)
    colored = 0
    for line in rows:
        r, g, b = line[0::channels], line[1::channels], line[2::channels]
        colored += sum(1 for x, y, z in zip(r, g, b) if max(x, y, z) - min(x, y, z) >= 24)
    fraction = colored / (width * height)
    print(f"{path}: {colored} colored pixels of {width}x{height} ({fraction:.1%})")
    return 0 if fraction >= minimum else 1


if __name__ == "__main__":
    sys.exit(main())
