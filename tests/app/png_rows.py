"""Reads a PNG as RGBA rows with the filters undone (the viewer tests' checks;
no imaging library needed)."""
import struct, zlib
def read(path):
    data = open(path, 'rb').read()
    assert data[:8] == b'\x89PNG\r\n\x1a\n', 'not a PNG'
    w, h = struct.unpack('>II', data[16:24])
    idat = b''; i = 8
    while i < len(data):
        n, kind = struct.unpack('>I4s', data[i:i + 8]); body = data[i + 8:i + 8 + n]
        if kind == b'IDAT': idat += body
        i += 12 + n
    raw = zlib.decompress(idat); stride = 4 * w + 1
    prev = bytearray(4 * w); rows = []
    for y in range(h):
        f = raw[y * stride]; row = bytearray(raw[y * stride + 1:(y + 1) * stride])
        for x in range(4 * w):
            a = row[x - 4] if x >= 4 else 0; b = prev[x]; c = prev[x - 4] if x >= 4 else 0
            if f == 1: row[x] = (row[x] + a) & 255
            elif f == 2: row[x] = (row[x] + b) & 255
            elif f == 3: row[x] = (row[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c; pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                row[x] = (row[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(row); prev = row
    return w, h, rows
