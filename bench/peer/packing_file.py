# -*- coding: utf-8 -*-
"""grainlab packing files for the peer scripts (no YADE import, so it can be tested on its own).

Reads format 2 (README "Packing files": a '# key value' header with the walls, the particle count,
the columns and an xxh64 checksum of every other byte of the file, then one row `id shape a b c x y z qw qx qy qz` per
particle) and format 1 (a comment line, the six wall planes, then `radius x y z` rows). The peer
scenes are spheres: an ellipsoid is refused; read_packing wants walls, read_periodic_packing a cell.
"""
import math

import xxhash  # Debian python3-xxhash

COLUMNS = "id shape a b c x y z qw qx qy qz".split()


class PackingError(ValueError):
    pass


def read_packing(path):
    """(planes xlo xhi ylo yhi zlo zhi, [(radius, x, y, z)]) of a grainlab packing file."""
    with open(path, "rb") as f:
        data = f.read()
    first = data.split(b"\n", 1)[0].decode("utf-8", "replace").split()
    if first[:2] == ["#", "grainlab-packing"]:
        if first[2:] != ["2"]:
            raise PackingError(f"{path}: packing format {' '.join(first[2:])} is not supported (1 and 2 are)")
        return _read_version2(path, data)
    return _read_version1(path, data.decode("utf-8"))


def read_periodic_packing(path):
    """(cell matrix H as three rows [m], [(radius, x, y, z)]) of a format-2 packing of a periodic cell."""
    with open(path, "rb") as f:
        data = f.read()
    if not data.startswith(b"# grainlab-packing 2\n"):
        raise PackingError(f"{path}: a periodic packing must be format 2")
    header, spheres = _parse_version2(path, data)
    if header.get("boundary", "").strip() != "periodic":
        raise PackingError(f"{path}: boundary {header.get('boundary')!r}: a periodic cell is needed")
    h = [_finite(v, path, 0) for v in header["cell"].split()]
    if len(h) != 9:
        raise PackingError(f"{path}: the cell line needs nine numbers")
    return [h[0:3], h[3:6], h[6:9]], spheres


def _finite(text, path, line):
    v = float(text)
    if not math.isfinite(v):
        raise PackingError(f"{path}: line {line}: {text} is not a finite number")
    return v


def _read_version2(path, data):
    header, spheres = _parse_version2(path, data)
    if header.get("boundary", "").strip() != "walls":
        raise PackingError(f"{path}: boundary {header.get('boundary')!r}: the peer scenes need walls")
    planes = [_finite(v, path, 0) for v in header["walls"].split()]
    if len(planes) != 6:
        raise PackingError(f"{path}: the walls line needs six planes")
    return planes, spheres


def _parse_version2(path, data):
    header, pos, line, checksum_line = {}, 0, 0, None
    while pos < len(data) and data[pos:pos + 1] == b"#":
        end = data.find(b"\n", pos)
        end = len(data) if end < 0 else end
        text = data[pos:end].decode("utf-8").rstrip("\r")
        if text.startswith("# xxh64 "):
            checksum_line = pos
        pos, line = end + 1, line + 1
        if line == 1:
            continue
        key, _, value = text[2:].partition(" ")
        header[key] = value
    body = data[pos:]
    # The checksum covers every byte but its own line.
    covered = data[:checksum_line] + body if checksum_line is not None else b""
    if "xxh64" in header and xxhash.xxh64(covered, seed=0).hexdigest() != header["xxh64"].strip().lower():
        raise PackingError(f"{path}: checksum mismatch: the file is corrupted or was edited")
    if header.get("columns", "").split() != COLUMNS:
        raise PackingError(f"{path}: columns must be {' '.join(COLUMNS)}")
    spheres = []
    for row in body.decode("utf-8").splitlines():
        line += 1
        f = row.split()
        if not f:
            continue
        if len(f) != len(COLUMNS) or f[1] != "sphere":
            raise PackingError(f"{path}: line {line}: expected a sphere row ({' '.join(COLUMNS)})")
        a, x, y, z = (_finite(f[i], path, line) for i in (2, 5, 6, 7))
        spheres.append((a, x, y, z))
    if len(spheres) != int(header["particles"]):
        raise PackingError(f"{path}: {len(spheres)} rows; the header says {header['particles']} particles")
    return header, spheres


def _read_version1(path, text):
    lines = [l for l in text.splitlines() if l.strip() and not l.lstrip().startswith('#')]
    planes = [_finite(v, path, 0) for v in lines[0].split()]
    spheres = [tuple(_finite(v, path, 0) for v in l.split()[:4]) for l in lines[1:]]
    if len(planes) != 6:
        raise PackingError(f"{path}: the first line must hold six wall planes")
    return planes, spheres
