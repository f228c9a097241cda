#!/usr/bin/env python3
"""Writes the hand-made input files of the io tests (deterministic; rerun
after changing this script and commit the bytes):

- tests/fixtures/: valid files in layouts our writers never produce (tiled
  and compressed TIFF, big-endian GeoTIFF in degrees, legacy Terragen, ESRI
  grids with centre corners and CRLF), read by tests/io/formats.rs;
- tests/malformed/: broken files of every format, one folder per format
  (tests/malformed/<format>/; the TIFFs a subfolder per what they break,
  tiff/<group>/), plus expected.json, the error variant and message
  substring each must produce (tests/io/malformed.rs). Some are cut from
  tests/golden/, so bless the golden files first.
"""
import json
import os
import struct
import zlib

ROOT = os.path.dirname(os.path.abspath(__file__))
GOLDEN = os.path.join(ROOT, "golden")
FIX = os.path.join(ROOT, "fixtures")
BAD = os.path.join(ROOT, "malformed")


def golden(name):
    with open(os.path.join(GOLDEN, name), "rb") as f:
        return f.read()


def put(directory, name, data):
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(directory, name), "wb") as f:
        f.write(data)


# ---------------------------------------------------------------- TIFF

TYPE_FMT = {1: "B", 2: "s", 3: "H", 4: "I", 11: "f", 12: "d", 16: "Q"}


def tiff(tags, chunks, le=True, tiled=False):
    """A classic TIFF: header, chunk data, then the IFD and its values.
    `tags` maps tag -> (type, values); chunk offsets/byte counts are added."""
    e = "<" if le else ">"
    out = bytearray(b"II*\x00" if le else b"MM\x00*")
    out += b"\0\0\0\0"
    offsets, counts = [], []
    for c in chunks:
        offsets.append(len(out))
        counts.append(len(c))
        out += c
        if len(out) % 2:
            out += b"\0"
    tags = dict(tags)
    tags[324 if tiled else 273] = (4, offsets)
    tags[325 if tiled else 279] = (4, counts)
    ifd = len(out)
    struct.pack_into(e + "I", out, 4, ifd)
    n = len(tags)
    values_at = ifd + 2 + 12 * n + 4
    entries, blob = bytearray(), bytearray()
    for tag in sorted(tags):
        ty, vals = tags[tag]
        if ty == 2:
            raw = vals.encode() + b"\0"
            count = len(raw)
        else:
            raw = struct.pack(e + TYPE_FMT[ty] * len(vals), *vals)
            count = len(vals)
        if len(raw) <= 4:
            field = raw.ljust(4, b"\0")
        else:
            field = struct.pack(e + "I", values_at + len(blob))
            blob += raw
            if len(blob) % 2:
                blob += b"\0"
        entries += struct.pack(e + "HHI", tag, ty, count) + field
    out += struct.pack(e + "H", n) + entries + b"\0\0\0\0" + blob
    return bytes(out)


def gray_tags(w, h, bits, fmt, rows=None):
    t = {
        256: (4, [w]),
        257: (4, [h]),
        258: (3, [bits]),
        259: (3, [1]),
        262: (3, [1]),
        277: (3, [1]),
        339: (3, [fmt]),
    }
    if rows is not None:
        t[278] = (4, [rows])
    return t


def fixtures():
    # Tiled int16, 20x18 in 16x16 tiles, GDAL_NODATA -32768, metres.
    w, h, tile = 20, 18, 16
    val = lambda x, y: -32768 if (x, y) == (3, 4) else x * 100 - y * 7
    tiles = []
    for ty in range(0, h, tile):
        for tx in range(0, w, tile):
            samples = []
            for y in range(ty, ty + tile):
                for x in range(tx, tx + tile):
                    samples.append(val(x, y) if x < w and y < h else 0)
            tiles.append(struct.pack("<%dh" % len(samples), *samples))
    t = gray_tags(w, h, 16, 2)
    t.update({322: (3, [tile]), 323: (3, [tile]), 33550: (12, [5.0, 5.0, 0.0]),
              33922: (12, [0, 0, 0, 1000.0, 2000.0, 0]), 42113: (2, "-32768")})
    put(FIX, "tiled_i16.tif", tiff(t, tiles, tiled=True))

    # uint16 in Deflate strips of 3 rows, pixel-is-point, US feet.
    w, h = 9, 7
    rows = []
    for y in range(h):
        rows.append(struct.pack("<%dH" % w, *[1000 + 10 * x + y for x in range(w)]))
    strips = [zlib.compress(b"".join(rows[i:i + 3])) for i in range(0, h, 3)]
    t = gray_tags(w, h, 16, 1, rows=3)
    t[259] = (3, [8])
    t.update({33550: (12, [10.0, 10.0, 0.0]), 33922: (12, [0, 0, 0, 100.0, 200.0, 0]),
              34735: (3, [1, 1, 0, 3, 1024, 0, 1, 1, 1025, 0, 1, 2, 3076, 0, 1, 9002])})
    put(FIX, "strips_u16_deflate.tif", tiff(t, strips))

    # Big-endian float32, geographic (degrees), NaN void, one strip.
    w, h = 6, 4
    vals = [float("nan") if (x, y) == (5, 0) else 100.5 + x - 2 * y for y in range(h) for x in range(w)]
    t = gray_tags(w, h, 32, 3)
    t.update({33550: (12, [1 / 1200, 1 / 1200, 0.0]), 33922: (12, [0, 0, 0, 1.0, 42.0, 0]),
              34735: (3, [1, 1, 0, 1, 1024, 0, 1, 2])})
    put(FIX, "geographic_f32_be.tif", tiff(t, [struct.pack(">%df" % len(vals), *vals)], le=False))

    # Terragen as old writers made it: square via SIZE only, CRAD/CRVM,
    # SCAL 10/10/2, odd sample count with its 2 pad bytes, then EOF.
    n = 5
    ter = bytearray(b"TERRAGENTERRAIN ")
    ter += b"SIZE" + struct.pack("<Hxx", n - 1)
    ter += b"SCAL" + struct.pack("<3f", 10, 10, 2)
    ter += b"CRAD" + struct.pack("<f", 6370) + b"CRVM" + struct.pack("<I", 0)
    ter += b"ALTW" + struct.pack("<hh", 1000, 50)
    # Stored south to north: stored row r is our row n-1-r.
    for r in range(n):
        y = n - 1 - r
        ter += struct.pack("<%dh" % n, *[(x - 2 * y) * 1000 for x in range(n)])
    ter += b"\0\0EOF "
    put(FIX, "legacy.ter", bytes(ter))

    # ESRI grid: CRLF, upper-case keywords, centre corner, wrapped rows,
    # NODATA_value and a nan.
    put(FIX, "centre.asc",
        "NCOLS 4\r\nNROWS 3\r\nXLLCENTER 105\r\nYLLCENTER 205\r\nCELLSIZE 10\r\nNODATA_VALUE -1\r\n"
        "1 2 3\r\n4 5.5 -1\r\n7 8\r\nnan 10 11 12\r\n")


# ---------------------------------------------------------------- PNG

def png_chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def png(w, h, depth, color, raw=None):
    ihdr = struct.pack(">IIBBBBB", w, h, depth, color, 0, 0, 0)
    idat = zlib.compress(raw if raw is not None else b"\0")
    return b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", ihdr) + png_chunk(b"IDAT", idat) + png_chunk(b"IEND", b"")


# ---------------------------------------------------------------- EXR

def exr_attr(name, kind, value):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value


def exr_header(w, h, channels, compression=0):
    chlist = b"".join(n.encode() + b"\0" + struct.pack("<iB3xii", t, 0, 1, 1) for n, t in channels) + b"\0"
    box = struct.pack("<4i", 0, 0, w - 1, h - 1)
    return (b"\x76\x2f\x31\x01" + b"\x02\0\0\0"
            + exr_attr("channels", "chlist", chlist)
            + exr_attr("compression", "compression", bytes([compression]))
            + exr_attr("dataWindow", "box2i", box)
            + exr_attr("displayWindow", "box2i", box)
            + exr_attr("lineOrder", "lineOrder", b"\0")
            + exr_attr("pixelAspectRatio", "float", struct.pack("<f", 1))
            + exr_attr("screenWindowCenter", "v2f", struct.pack("<2f", 0, 0))
            + exr_attr("screenWindowWidth", "float", struct.pack("<f", 1))
            + b"\0")


# ---------------------------------------------------------------- malformed

# The broken TIFFs by what they break: the file's structure (header,
# directories, data ranges), its samples (size, type, bands), its GeoTIFF
# and GDAL tags; the LERC ones have tiff/lerc/.
TIFF_GROUPS = {
    name: group
    for group, names in {
        "structure": "bad_magic bad_version truncated bigtiff_far_ifd tag_past_end strip_cut",
        "samples": "huge not_justified rgb i64 float16",
        "geo": "bad_nodata bad_scale geocentric bad_geokeys odd_unit",
    }.items()
    for name in ("tiff_%s.tif" % n for n in names.split())
}


def malformed():
    cases = {}

    def case(name, data, variant, contains, names=None, sidecar=None):
        # One folder per format (the name's prefix); the TIFFs, the most
        # numerous, in a subfolder per what they break (TIFF_GROUPS).
        folder = name.split("_")[0]
        if folder == "tiff":
            folder = "tiff/lerc" if name.startswith("tiff_lerc") else "tiff/" + TIFF_GROUPS[name]
        directory = os.path.join(BAD, folder)
        os.makedirs(directory, exist_ok=True)
        put(directory, name, data)
        if sidecar is not None:
            put(directory, os.path.splitext(name)[0] + ".json", sidecar)
        cases[folder + "/" + name] = {"variant": variant, "contains": contains, "names": names or name}

    # PNG
    g = golden("png16.png")
    case("png_bad_magic.png", b"GIF89a\x01\x00\x01\x00", "BadMagic", "PNG signature")
    case("png_empty.png", b"", "BadMagic", "an empty file")
    case("png_truncated.png", g[:60], "EndsEarly", "PNG stream")
    case("png_rgb.png", png(2, 2, 8, 2, b"\0" + b"\0" * 6 + b"\0" + b"\0" * 6), "Unsupported", "PNG colour type")
    case("png_2bit.png", png(4, 1, 2, 0, b"\0\0"), "Unsupported", "2 bits")
    case("png_huge.png", png(100000, 100000, 16, 0), "Size", "100000x100000 is too large")
    case("png_not_justified.png", png(20000, 20000, 16, 0), "SizeNotJustified", "20000x20000")
    bad_crc = bytearray(g)
    bad_crc[29] ^= 0xFF  # IHDR CRC
    case("png_bad_crc.png", bytes(bad_crc), "Corrupt", "CRC")
    case("png_bad_sidecar.png", g, "InvalidSidecar", "not JSON",
         names="png_bad_sidecar.json", sidecar="{ oops")
    case("png_sidecar_size.png", g, "InvalidSidecar", "width is 9 but the data file is 7",
         names="png_sidecar_size.json", sidecar='{"scale_m": 1, "width": 9}')

    # EXR
    g = golden("exr.exr")
    case("exr_bad_magic.exr", b"\x76\x2f\x31\x02" + g[4:64], "BadMagic", "OpenEXR magic")
    case("exr_header_cut.exr", g[:40], "EndsEarly", "the EXR data ends early")
    case("exr_truncated.exr", g[: len(g) - 60], "EndsEarly", "the EXR data ends early")
    # A 2x2 ZIP-compressed (one block of 16 lines) image whose block is garbage.
    head = exr_header(2, 2, [("Y", 2)], compression=3)
    block = struct.pack("<ii", 0, 6) + b"\xff" * 6
    case("exr_bad_zip.exr", head + struct.pack("<Q", len(head) + 8) + block, "Corrupt", "EXR")
    case("exr_huge.exr", exr_header(100000, 100000, [("Y", 2)]), "Size", "100000x100000 is too large")
    case("exr_not_justified.exr", exr_header(20000, 20000, [("Y", 2)]), "SizeNotJustified", "20000x20000")
    case("exr_rgbz.exr", exr_header(2, 2, [("B", 2), ("G", 2), ("R", 2), ("Z", 2)]), "Unsupported", "EXR channels: B, G, R, Z")
    case("exr_u32.exr", exr_header(2, 2, [("Z", 0)]), "Unsupported", "u32 in channel Z")
    key = b"cellSizeMetres\0double\0" + struct.pack("<i", 8)
    i = g.index(key) + len(key)
    case("exr_bad_cell_size.exr", g[:i] + struct.pack("<d", -1.0) + g[i + 8:], "Metadata",
         "cellSizeMetres is -1")

    # TIFF
    g = golden("tiff.tif")
    small = gray_tags(2, 2, 16, 1)
    pix = [b"\1\0\2\0\3\0\4\0"]
    case("tiff_bad_magic.tif", b"XX*\0" + g[4:40], "BadMagic", "TIFF header")
    case("tiff_bad_version.tif", b"II\x2c\0" + g[4:40], "BadMagic", "TIFF header")
    case("tiff_truncated.tif", g[:200], "Truncated", "the first TIFF directory")
    case("tiff_strip_cut.tif", tiff_strip_cut(), "EndsEarly", "TIFF data")
    case("tiff_huge.tif", tiff(gray_tags(100000, 100000, 16, 1), pix), "Size", "100000x100000 is too large")
    case("tiff_not_justified.tif", tiff(gray_tags(20000, 20000, 16, 1), pix), "SizeNotJustified", "20000x20000")
    rgb = gray_tags(2, 2, 8, 1)
    rgb.update({258: (3, [8, 8, 8]), 262: (3, [2]), 277: (3, [3]), 339: (3, [1, 1, 1])})
    case("tiff_rgb.tif", tiff(rgb, [b"\0" * 12]), "Unsupported", "3 bands")
    case("tiff_i64.tif", tiff(gray_tags(2, 2, 64, 2), [b"\0" * 32]), "Unsupported", "64-bit Int")
    t = dict(small)
    t[259] = (3, [34887])
    case("tiff_lerc.tif", tiff(t, pix), "Corrupt", "LERC strip 0: blob 1 is not a complete Lerc2 header")
    case("tiff_lerc_wrong_size.tif", tiff(t, [lerc2_constant(3, 3, 3, 5.0)]), "Corrupt",
         "LERC strip 0: its Lerc2 blob is 3x3, the chunk 2x2")
    bad = bytearray(lerc2_constant(2, 2, 3, 5.0))
    bad[-1] ^= 0x40
    case("tiff_lerc_checksum.tif", tiff(t, [bytes(bad)]), "Corrupt", "LERC strip 0: Lerc2")
    case("tiff_lerc_past_end.tif", lerc_strip_past_end(t), "Corrupt",
         "LERC strip 0: bytes 8..1000008 lie past the end")
    tz = dict(t)
    tz[50674] = (4, [4, 2])
    case("tiff_lerc_zstd_garbage.tif", tiff(tz, [b"\x28\xb5\x2f\xfd" + b"\xff" * 12]), "Corrupt",
         "LERC strip 0: its zstd layer")
    td = dict(t)
    td[50674] = (4, [4, 1])
    # A zlib stream of 2000 bytes where a 2x2 uint16 chunk allows 266.
    case("tiff_lerc_deflate_long.tif", tiff(td, [zlib.compress(b"\0" * 2000)]), "Corrupt",
         "LERC strip 0: its deflate layer")
    tw = dict(t)
    tw[50674] = (4, [4, 7])
    case("tiff_lerc_unknown_layer.tif", tiff(tw, [lerc2_constant(2, 2, 3, 5.0)]), "Unsupported",
         "7 (LercParameters, tag 50674)")
    big = gray_tags(20000, 20000, 16, 1)
    big[259] = (3, [34887])
    case("tiff_lerc_not_justified.tif", tiff(big, [lerc2_constant(20000, 20000, 3, 5.0)]),
         "SizeNotJustified", "20000x20000")
    case("tiff_float16.tif", tiff(gray_tags(2, 2, 16, 3), pix), "Unsupported", "16-bit IEEEFP")
    t = dict(small)
    t[42113] = (2, "abc")
    case("tiff_bad_nodata.tif", tiff(t, pix), "Metadata", 'GDAL_NODATA (tag 42113) is "abc"')
    t = dict(small)
    t[33550] = (12, [0.0, 0.0, 0.0])
    case("tiff_bad_scale.tif", tiff(t, pix), "Metadata", "ModelPixelScale (tag 33550) is 0 x 0")
    t = dict(small)
    t[34735] = (3, [1, 1, 0, 1, 1024, 0, 1, 3])
    case("tiff_geocentric.tif", tiff(t, pix), "Unsupported", "GeoTIFF model type: 3")
    t = dict(small)
    t[34735] = (3, [1, 1, 0, 5, 1024, 0, 1, 1])
    case("tiff_bad_geokeys.tif", tiff(t, pix), "Metadata", "declares 5 keys")
    t = dict(small)
    t[34735] = (3, [1, 1, 0, 1, 3076, 0, 1, 9036])
    t[33550] = (12, [1.0, 1.0, 0.0])
    case("tiff_odd_unit.tif", tiff(t, pix), "Unsupported", "EPSG 9036")
    case("tiff_tag_past_end.tif", tiff_tag_past_end(), "Metadata", "past the end")
    # Found by the fuzzer: a BigTIFF directory offset near 2^64 overflowed.
    case("tiff_bigtiff_far_ifd.tif", b"II+\0\x08\0\0\0" + b"\xff" * 8, "Truncated",
         "the first TIFF directory needs 18446744073709551615 bytes")

    # SRTM
    case("hgt_wrong_size.hgt", b"\0" * 1000, "DimensionMismatch", "this file has 1000")
    case("hgt_empty.hgt", b"", "DimensionMismatch", "this file has 0")

    # ESRI ASCII
    head = "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 10\n"
    case("asc_missing_ncols.asc", "nrows 2\ncellsize 1\n1 2\n3 4\n", "Syntax", "line 3: header has no ncols")
    case("asc_bad_number.asc", head + "1 2 3\n4 1.2.3 6\n", "Syntax", 'line 7: invalid number "1.2.3"')
    case("asc_too_few.asc", head + "10 20 30\n40 50\n", "Syntax", "line 7: the grid ends early: expected ncols x nrows = 6 values, found 5")
    case("asc_too_many.asc", head + "1 2 3\n4 5 6\n7\n", "Syntax", "line 8: more values than ncols x nrows")
    case("asc_huge.asc", "ncols 100000\nnrows 100000\ncellsize 1\n1 2 3\n", "Size", "100000x100000 is too large")
    case("asc_not_justified.asc", "ncols 1000\nnrows 1000\ncellsize 1\n1 2 3\n", "SizeNotJustified", "1000x1000")
    case("asc_bad_cellsize.asc", "ncols 1\nnrows 1\ncellsize -5\n1\n", "Syntax", "line 3: cellsize is -5")
    case("asc_unknown_key.asc", "ncols 1\nnrows 1\ncellsize 1\nprojection 5\n1\n", "Syntax", 'line 4: unknown header keyword "projection"')
    case("asc_duplicate.asc", "ncols 1\nncols 1\nnrows 1\ncellsize 1\n1\n", "Syntax", "line 2: ncols is given twice")
    case("asc_half_corner.asc", "ncols 1\nnrows 1\ncellsize 1\nxllcorner 5\n1\n", "Syntax", "one is given without the other")
    case("asc_binary.asc", bytes(range(256)) * 2, "Syntax", "line 1: header has no ncols")
    case("asc_infinite.asc", "ncols 2\nnrows 1\ncellsize 1\n1 inf\n", "Size", "pixel (1, 0) is infinite")
    case("asc_zero_rows.asc", "ncols 2\nnrows 0\ncellsize 1\n", "Syntax", "nrows is \"0\"")

    # Raw
    case("r16_not_square.r16", b"\0" * 12, "DimensionMismatch", "6 R16 samples do not form a square")
    case("r16_odd_bytes.r16", b"\0" * 7, "DimensionMismatch", "7 bytes is not a whole number of 2-byte R16 samples")
    case("r16_empty.r16", b"", "DimensionMismatch", "0 bytes")
    case("r16_bad_sidecar.r16", b"\0" * 8, "InvalidSidecar", "width is 0",
         names="r16_bad_sidecar.json", sidecar='{"scale_m": 1, "width": 0, "height": 2}')
    case("r32_sidecar_mismatch.r32", b"\0" * 64, "DimensionMismatch",
         "5x5 from the sidecar needs 100 bytes of R32", sidecar='{"scale_m": 1, "width": 5, "height": 5}')
    case("r32_infinite.r32", struct.pack("<4f", 1, 2, float("inf"), 4), "Size", "pixel (0, 1) is infinite")

    # Terragen
    g = golden("ter.ter")
    case("ter_bad_magic.ter", b"TERRAGENTERRAIX " + g[16:], "BadMagic", "TERRAGENTERRAIN")
    case("ter_truncated.ter", g[:100], "Truncated", "the ALTW samples needs 134 bytes, the file has 100")
    case("ter_cut_chunk.ter", g[:46], "Truncated", "the SCAL chunk")
    case("ter_no_altw.ter", b"TERRAGENTERRAIN SIZE\x04\0\0\0EOF ", "Corrupt", "no ALTW")
    case("ter_altw_first.ter", b"TERRAGENTERRAIN ALTW\0\0\0\0EOF ", "Corrupt", "before any SIZE")
    case("ter_unknown_chunk.ter", b"TERRAGENTERRAIN SIZE\x04\0\0\0JUNK\0\0\0\0", "Corrupt", 'unknown Terragen chunk "JUNK" at byte 24')
    case("ter_huge.ter", b"TERRAGENTERRAIN SIZE\xfe\xff\0\0XPTS\xff\xff\0\0YPTS\xff\xff\0\0ALTW\0\0\0\0",
         "Size", "65535x65535 is too large")
    case("ter_not_justified.ter", b"TERRAGENTERRAIN SIZE\xe7\x03\0\0ALTW\1\0\0\0\0\0\0\0", "Truncated",
         "the ALTW samples needs 2000032 bytes")
    case("ter_bad_scal.ter", g[:44] + struct.pack("<f", 0) + g[48:], "Metadata", "SCAL is 0 x 2.5 x 2.5")
    case("ter_nonsquare.ter", g[:48] + struct.pack("<f", 5) + g[52:], "Unsupported", "SCAL 2.5 x 5 m")

    with open(os.path.join(BAD, "expected.json"), "w") as f:
        json.dump(cases, f, indent=1, sort_keys=True)
        f.write("\n")


def tiff_strip_cut():
    """A 4x4 uint16 strip whose byte count runs past the end of the file."""
    t = gray_tags(4, 4, 16, 1)
    data = bytearray(tiff(t, [b"\1\0" * 16]))
    # The strip sits at offset 8; move it to just before the end of the file.
    n = struct.unpack_from("<H", data, 8 + 32)[0]
    for k in range(n):
        e = 8 + 32 + 2 + 12 * k
        tag = struct.unpack_from("<H", data, e)[0]
        if tag == 273:
            struct.pack_into("<I", data, e + 8, len(data) - 10)
    return bytes(data)


def fletcher32(data):
    """Lerc2's checksum of a blob's bytes after its first 14."""
    s1 = s2 = 0xFFFF
    words = len(data) // 2
    i = 0
    while words:
        n = min(words, 359)
        words -= n
        for _ in range(n):
            s1 += data[i] << 8
            s1 += data[i + 1]
            s2 += s1
            i += 2
        s1 = (s1 & 0xFFFF) + (s1 >> 16)
        s2 = (s2 & 0xFFFF) + (s2 >> 16)
    if len(data) & 1:
        s1 += data[i] << 8
        s2 += s1
    s1 = (s1 & 0xFFFF) + (s1 >> 16)
    s2 = (s2 & 0xFFFF) + (s2 >> 16)
    return (s2 << 16 | s1) & 0xFFFFFFFF


def lerc2_constant(w, h, dtype, z):
    """A Lerc2 v3 blob of a constant w x h chunk (no mask, no data block):
    dtype is Lerc2's type code (1 byte, 3 uint16, 6 float32)."""
    body = struct.pack("<6i", h, w, w * h, 8, 0, dtype) + struct.pack("<3d", 0.5, z, z)
    body += struct.pack("<i", 0)
    size = 6 + 4 + 4 + len(body)
    body = struct.pack("<6i", h, w, w * h, 8, size, dtype) + body[24:]
    return b"Lerc2 " + struct.pack("<i", 3) + struct.pack("<I", fletcher32(body)) + body


def patch_entry(data, tag, at, value):
    """`data` (a one-IFD little-endian TIFF) with the u32 `at` bytes into
    `tag`'s IFD entry (4: its count, 8: its value or offset) set to `value`."""
    data = bytearray(data)
    ifd = struct.unpack_from("<I", data, 4)[0]
    n = struct.unpack_from("<H", data, ifd)[0]
    for k in range(n):
        e = ifd + 2 + 12 * k
        if struct.unpack_from("<H", data, e)[0] == tag:
            struct.pack_into("<I", data, e + at, value)
    return bytes(data)


def lerc_strip_past_end(tags):
    """A 2x2 LERC image whose strip byte count claims a million bytes."""
    data = tiff(tags, [lerc2_constant(2, 2, 3, 5.0)])
    return patch_entry(data, 279, 8, 1_000_000)


def tiff_tag_past_end():
    """A 2x2 image whose ImageDescription claims a million bytes."""
    t = gray_tags(2, 2, 16, 1)
    t[270] = (2, "x" * 8)
    data = tiff(t, [b"\1\0\2\0\3\0\4\0"])
    return patch_entry(data, 270, 4, 1_000_000)


if __name__ == "__main__":
    os.makedirs(FIX, exist_ok=True)
    os.makedirs(BAD, exist_ok=True)
    fixtures()
    malformed()
