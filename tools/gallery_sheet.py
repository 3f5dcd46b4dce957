#!/usr/bin/env python3
"""Contact sheets for the gallery (tools/gallery.sh), with the Python standard library only.

  gallery_sheet.py sheet OUT.png --columns C [--labels L1,L2,...] TILE.png ...
      Lays the tiles (8-bit RGB or RGBA PNGs of one size, e.g. a run's preview.####.png) out
      in rows of C, as `shellmpm`'s own contact_sheet.png does (render/image.cpp
      contact_sheet): a 4-pixel gap, a dark grey (24) background, each tile's label
      (its frame number) in the 3x5 digit font at its bottom left. Writes an 8-bit RGB PNG.

  gallery_sheet.py check IMAGE.png [--min-width W] [--min-height H] [--max-bytes B]
      Exits 0 when IMAGE.png is a valid PNG (signature, chunk CRCs, IHDR, the image data
      inflates to the declared size) at least W x H pixels and at most B bytes, and not
      trivial: at least a tenth of the pixels differ from the top-left pixel and the pixel
      values' standard deviation is at least 8 (of 255). Prints its figures; exits 1 with
      the reason otherwise.

Only what libpng writes for shellmpm is read: 8 bits per channel, colour types 0, 2 and 6
(grey, RGB, RGBA), no interlacing; anything else is refused by name.
"""

import argparse
import os
import struct
import sys
import zlib

SIGNATURE = b"\x89PNG\r\n\x1a\n"
GAP = 4  # render/image.cpp contact_sheet
BACKGROUND = 24
CHANNELS = {0: 1, 2: 3, 6: 4}  # colour type -> channels (8-bit only)

# render/image.cpp glyph(): 3x5 digits, one row per 3 bits (MSB = left column).
DIGITS = [
    (7, 5, 5, 5, 7), (2, 6, 2, 2, 7), (7, 1, 7, 4, 7), (7, 1, 7, 1, 7), (5, 5, 7, 1, 1),
    (7, 4, 7, 1, 7), (7, 4, 7, 5, 7), (7, 1, 1, 1, 1), (7, 5, 7, 5, 7), (7, 5, 7, 1, 7),
]  # fmt: skip


class PngError(Exception):
    """A file that is not a PNG this script reads; the message names the file."""


class Image:
    """8-bit RGB pixels, row-major: `rgb` is a bytearray of width * height * 3."""

    def __init__(self, width, height, fill=0):
        self.width, self.height = width, height
        self.rgb = bytearray([fill]) * (width * height * 3)


def _paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    return b if pb <= pc else c


def _unfilter(raw, width, height, bpp, path):
    """The filtered scanlines `raw` (each with its filter byte) as one bytearray of rows."""
    stride = width * bpp
    if len(raw) != height * (stride + 1):
        raise PngError(f"{path}: image data is {len(raw)} bytes, expected {height * (stride + 1)}")
    out = bytearray(height * stride)
    prev = bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        ftype = raw[start]
        line = bytearray(raw[start + 1:start + 1 + stride])
        if ftype == 1:  # Sub
            for i in range(bpp, stride):
                line[i] = (line[i] + line[i - bpp]) & 255
        elif ftype == 2:  # Up
            line = bytearray((a + b) & 255 for a, b in zip(line, prev))
        elif ftype == 3:  # Average
            for i in range(stride):
                left = line[i - bpp] if i >= bpp else 0
                line[i] = (line[i] + ((left + prev[i]) >> 1)) & 255
        elif ftype == 4:  # Paeth
            for i in range(stride):
                left = line[i - bpp] if i >= bpp else 0
                upleft = prev[i - bpp] if i >= bpp else 0
                line[i] = (line[i] + _paeth(left, prev[i], upleft)) & 255
        elif ftype != 0:
            raise PngError(f"{path}: row {y} has unknown filter type {ftype}")
        out[y * stride:(y + 1) * stride] = line
        prev = line
    return out


def read_png(path):
    """The PNG at `path` as an Image (grey and alpha dropped to RGB); PngError otherwise."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        raise PngError(f"{path}: cannot read: {e}") from e
    if not data.startswith(SIGNATURE):
        raise PngError(f"{path}: not a PNG file (bad signature)")
    pos, header, idat, ended = len(SIGNATURE), None, [], False
    while pos + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if len(body) != length or pos + 12 + length > len(data):
            raise PngError(f"{path}: chunk {kind!r} runs past the end of the file")
        (crc,) = struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])
        if zlib.crc32(kind + body) & 0xFFFFFFFF != crc:
            raise PngError(f"{path}: chunk {kind!r} has a bad CRC")
        pos += 12 + length
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            ended = True
            break
    if header is None or not idat or not ended:
        raise PngError(f"{path}: missing IHDR, IDAT or IEND chunk (truncated?)")
    width, height, depth, ctype, _comp, _filt, interlace = header
    if width == 0 or height == 0:
        raise PngError(f"{path}: empty image ({width}x{height})")
    if depth != 8 or ctype not in CHANNELS or interlace != 0:
        raise PngError(
            f"{path}: bit depth {depth}, colour type {ctype}, interlace {interlace} "
            "(this script reads 8-bit grey, RGB or RGBA, not interlaced)"
        )
    try:
        raw = zlib.decompress(b"".join(idat))
    except zlib.error as e:
        raise PngError(f"{path}: image data does not inflate: {e}") from e
    bpp = CHANNELS[ctype]
    px = _unfilter(raw, width, height, bpp, path)
    im = Image(width, height)
    if bpp == 3:
        im.rgb[:] = px
    else:
        for c in range(3):
            im.rgb[c::3] = px[0 if bpp == 1 else c::bpp]
    return im


def write_png(path, im):
    """Writes `im` as an 8-bit RGB PNG (per-row filter by the minimum-sum heuristic, zlib
    level 9) to a temporary name, then renames it."""
    stride = im.width * 3
    rows = []
    prev = bytes(stride)
    for y in range(im.height):
        line = bytes(im.rgb[y * stride:(y + 1) * stride])
        sub = bytes((line[i] - (line[i - 3] if i >= 3 else 0)) & 255 for i in range(stride))
        up = bytes((a - b) & 255 for a, b in zip(line, prev))
        paeth = bytes(
            (line[i] - _paeth(line[i - 3] if i >= 3 else 0, prev[i], prev[i - 3] if i >= 3 else 0))
            & 255
            for i in range(stride)
        )
        cands = [(0, line), (1, sub), (2, up), (4, paeth)]
        ftype, best = min(cands, key=lambda fc: sum(v if v < 128 else 256 - v for v in fc[1]))
        rows.append(bytes([ftype]) + best)
        prev = line

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(
            ">I", zlib.crc32(kind + body) & 0xFFFFFFFF
        )

    ihdr = struct.pack(">IIBBBBB", im.width, im.height, 8, 2, 0, 0, 0)
    data = SIGNATURE + chunk(b"IHDR", ihdr)
    data += chunk(b"IDAT", zlib.compress(b"".join(rows), 9)) + chunk(b"IEND", b"")
    tmp = f"{path}.tmp{os.getpid()}"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def draw_label(im, x0, y0, text, scale):
    """Digits in white over a dark shadow, as render/image.cpp draw_label."""
    for shadow in (True, False):
        off = scale // 2 + 1 if shadow else 0
        v = 20 if shadow else 255
        for i, ch in enumerate(text):
            if not ch.isdigit():
                continue
            for r, bits in enumerate(DIGITS[int(ch)]):
                for c in range(3):
                    if not bits & (4 >> c):
                        continue
                    for sy in range(scale):
                        for sx in range(scale):
                            x = x0 + i * 4 * scale + c * scale + sx + off
                            y = y0 + r * scale + sy + off
                            if 0 <= x < im.width and 0 <= y < im.height:
                                k = 3 * (y * im.width + x)
                                im.rgb[k:k + 3] = bytes((v, v, v))


def contact_sheet(tiles, labels, columns):
    """The tiles in rows of `columns`, as render/image.cpp contact_sheet lays them out."""
    tw, th = tiles[0].width, tiles[0].height
    n = len(tiles)
    columns = max(1, min(columns, n))
    rows = (n + columns - 1) // columns
    sheet = Image(columns * tw + (columns + 1) * GAP, rows * th + (rows + 1) * GAP, BACKGROUND)
    scale = max(1, th // 60)
    for i, t in enumerate(tiles):
        ox, oy = GAP + (i % columns) * (tw + GAP), GAP + (i // columns) * (th + GAP)
        for y in range(th):
            d = 3 * ((oy + y) * sheet.width + ox)
            sheet.rgb[d:d + 3 * tw] = t.rgb[3 * y * tw:3 * (y + 1) * tw]
        if i < len(labels) and labels[i]:
            draw_label(sheet, ox + 2 * scale, oy + th - 7 * scale, labels[i], scale)
    return sheet


def cmd_sheet(args):
    tiles = [read_png(p) for p in args.tiles]
    for p, t in zip(args.tiles, tiles):
        if (t.width, t.height) != (tiles[0].width, tiles[0].height):
            raise PngError(
                f"{p}: {t.width}x{t.height}, but {args.tiles[0]} is "
                f"{tiles[0].width}x{tiles[0].height} (tiles must share one size)"
            )
    labels = args.labels.split(",") if args.labels else []
    if labels and len(labels) != len(tiles):
        raise PngError(f"--labels: {len(labels)} labels for {len(tiles)} tiles")
    sheet = contact_sheet(tiles, labels, args.columns)
    write_png(args.out, sheet)
    print(f"{args.out}: {sheet.width}x{sheet.height}, {os.path.getsize(args.out)} bytes")
    return 0


def cmd_check(args):
    im = read_png(args.image)
    size = os.path.getsize(args.image)
    n = im.width * im.height
    first = bytes(im.rgb[0:3])
    differ = sum(1 for i in range(0, 3 * n, 3) if im.rgb[i:i + 3] != first)
    mean = sum(im.rgb) / (3 * n)
    std = (sum((v - mean) ** 2 for v in im.rgb) / (3 * n)) ** 0.5
    print(
        f"{args.image}: {im.width}x{im.height}, {size} bytes, {differ / n:.3f} of the pixels "
        f"differ from the corner, standard deviation {std:.1f}"
    )
    problems = []
    if im.width < args.min_width or im.height < args.min_height:
        problems.append(f"smaller than {args.min_width}x{args.min_height}")
    if args.max_bytes and size > args.max_bytes:
        problems.append(f"larger than {args.max_bytes} bytes")
    if differ < 0.1 * n:
        problems.append("under a tenth of the pixels differ from the corner (blank?)")
    if std < 8.0:
        problems.append("pixel standard deviation under 8 (flat?)")
    if problems:
        print(f"{args.image}: " + "; ".join(problems), file=sys.stderr)
        return 1
    return 0


def main(argv):
    p = argparse.ArgumentParser(prog="gallery_sheet.py", description=__doc__.split("\n")[0])
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("sheet", help="lay PNG tiles out as a contact sheet")
    s.add_argument("out", metavar="OUT.png")
    s.add_argument("tiles", metavar="TILE.png", nargs="+")
    s.add_argument("--columns", type=int, default=2)
    s.add_argument("--labels", help="comma-separated label per tile (digits)")
    c = sub.add_parser("check", help="is IMAGE.png a valid, non-trivial PNG")
    c.add_argument("image", metavar="IMAGE.png")
    c.add_argument("--min-width", type=int, default=1)
    c.add_argument("--min-height", type=int, default=1)
    c.add_argument("--max-bytes", type=int, default=0, help="0: no limit")
    args = p.parse_args(argv)
    try:
        return cmd_sheet(args) if args.command == "sheet" else cmd_check(args)
    except PngError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
