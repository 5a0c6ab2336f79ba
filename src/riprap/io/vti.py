"""Uniform-grid fields as VTK XML ImageData (``.vti``), which ParaView opens directly.

Cell data only (the fluid's cell-centred fields). Arrays are stored as float32 (enough for
pictures; the checkpoint keeps float64), zlib-compressed, appended raw after the XML header
(``header_type="UInt64"``), each as one compressed block: header [1, raw size, raw size,
compressed size] then the bytes. VTK orders cells with x fastest, so riprap's [i, j, k] arrays are
written in Fortran order. The file is written to a temporary name and moved into place.

A run over several processes writes its frames as ParaView's parallel image data: each process a
``.vti`` piece of its own x-planes (:func:`write_vti` with ``start``, the piece's first cell in
the whole grid), process 0 a ``.pvti`` naming the pieces (:func:`write_pvti`), which the ``.pvd``
lists; :func:`read_pvti` joins the pieces back.
"""
from __future__ import annotations

import os
import zlib
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError
from riprap.io.output_folder import naming_the_file

__all__ = ["write_vti", "read_vti", "write_pvti", "read_pvti"]


def _block(array: np.ndarray) -> bytes:
    raw = np.ascontiguousarray(array).tobytes()
    packed = zlib.compress(raw, 1)
    return np.array([1, len(raw), len(raw), len(packed)], dtype="<u8").tobytes() + packed


def write_vti(path, *, origin, spacing: float, cells, cell_data, start=(0, 0, 0)) -> Path:
    """Write ``cell_data`` (name -> array of shape ``cells`` or ``cells + (3,)``) on the grid of
    ``cells`` = (nx, ny, nz) cubes of side ``spacing`` from ``origin`` (m). ``start``: the
    first cell's index in a larger grid whose corner is ``origin`` (a piece of a ``.pvti``)."""
    path = Path(path)
    nx, ny, nz = (int(n) for n in cells)
    i0, j0, k0 = (int(n) for n in start)
    ox, oy, oz = (float(v) for v in origin)
    arrays, blocks, offset = [], [], 0
    for name, values in cell_data.items():
        values = np.asarray(values)
        components = 1 if values.shape == (nx, ny, nz) else (
            values.shape[3] if values.ndim == 4 and values.shape[:3] == (nx, ny, nz) else 0)
        if components == 0:
            raise CaseFileError(f"writing {path}: field {name!r} has shape {values.shape}, "
                                f"expected ({nx}, {ny}, {nz}) or ({nx}, {ny}, {nz}, 3)")
        # x fastest: Fortran order over (i, j, k), components innermost.
        flat = values.astype("<f4").transpose(2, 1, 0, *range(3, values.ndim)).reshape(-1)
        block = _block(flat)
        arrays.append(f'<DataArray type="Float32" Name="{name}" NumberOfComponents="{components}" '
                      f'format="appended" offset="{offset}"/>')
        blocks.append(block)
        offset += len(block)
    extent = f"{i0} {i0 + nx} {j0} {j0 + ny} {k0} {k0 + nz}"
    header = (
        '<?xml version="1.0"?>\n'
        '<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64" '
        'compressor="vtkZLibDataCompressor">\n'
        f'<ImageData WholeExtent="{extent}" Origin="{ox!r} {oy!r} {oz!r}" '
        f'Spacing="{spacing!r} {spacing!r} {spacing!r}">\n'
        f'<Piece Extent="{extent}">\n<CellData>\n' + "\n".join(arrays) + "\n</CellData>\n"
        "</Piece>\n</ImageData>\n<AppendedData encoding=\"raw\">\n_")
    footer = "\n</AppendedData>\n</VTKFile>\n"
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(path.name + ".partial")
    with naming_the_file(path), open(temporary, "wb") as stream:
        stream.write(header.encode("ascii"))
        for block in blocks:
            stream.write(block)
        stream.write(footer.encode("ascii"))
    os.replace(temporary, path)
    return path


def read_vti(path) -> dict:
    """Read a file written by :func:`write_vti` back: {name: array (nx, ny, nz[, 3])}, float32.
    For tests and post-processing; ParaView reads the files itself."""
    import re

    data = Path(path).read_bytes()
    start = data.index(b'<AppendedData encoding="raw">\n_') + len(b'<AppendedData encoding="raw">\n_')
    text = data[:start].decode("ascii")
    extent = [int(v) for v in re.search(r'WholeExtent="([-\d ]+)"', text).group(1).split()]
    nx, ny, nz = (extent[2 * a + 1] - extent[2 * a] for a in range(3))
    fields = {}
    for name, components, offset in re.findall(
            r'Name="([^"]+)" NumberOfComponents="(\d+)" format="appended" offset="(\d+)"', text):
        position = start + int(offset)
        header = np.frombuffer(data[position:position + 32], dtype="<u8")
        raw = zlib.decompress(data[position + 32:position + 32 + int(header[3])])
        values = np.frombuffer(raw, dtype="<f4")
        components = int(components)
        shape = (nz, ny, nx) + ((components,) if components > 1 else ())
        values = values.reshape(shape).transpose(2, 1, 0, *range(3, len(shape)))
        fields[name] = values
    return fields


def write_pvti(path, *, origin, spacing: float, cells, fields: dict, pieces) -> Path:
    """Write the ``.pvti`` of a grid of ``cells`` cubes from ``origin`` whose pieces were written
    by :func:`write_vti`: ``pieces`` [(file name relative to ``path``'s folder, first x-cell,
    end x-cell)] covering the x-planes in order, each holding every y and z cell; ``fields``
    {name: components} as the pieces have them."""
    path = Path(path)
    nx, ny, nz = (int(n) for n in cells)
    ox, oy, oz = (float(v) for v in origin)
    ends = [0] + [int(stop) for _, _, stop in pieces]
    if [int(first) for _, first, _ in pieces] != ends[:-1] or ends[-1] != nx:
        raise CaseFileError(f"writing {path}: the pieces' x-planes "
                            f"{[(int(a), int(b)) for _, a, b in pieces]} do not cover 0 .. {nx}")
    arrays = "\n".join(f'<PDataArray type="Float32" Name="{name}" NumberOfComponents="{n}"/>'
                       for name, n in fields.items())
    listed = "\n".join(f'<Piece Extent="{first} {stop} 0 {ny} 0 {nz}" Source="{name}"/>'
                       for name, first, stop in pieces)
    text = ('<?xml version="1.0"?>\n'
            '<VTKFile type="PImageData" version="1.0" byte_order="LittleEndian" '
            'header_type="UInt64">\n'
            f'<PImageData WholeExtent="0 {nx} 0 {ny} 0 {nz}" GhostLevel="0" '
            f'Origin="{ox!r} {oy!r} {oz!r}" Spacing="{spacing!r} {spacing!r} {spacing!r}">\n'
            f"<PCellData>\n{arrays}\n</PCellData>\n{listed}\n</PImageData>\n</VTKFile>\n")
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(path.name + ".partial")
    with naming_the_file(path):
        temporary.write_text(text)
    os.replace(temporary, path)
    return path


def read_pvti(path) -> dict:
    """The whole grid's fields of a ``.pvti`` (:func:`write_pvti`), its pieces joined along x:
    {name: array (nx, ny, nz[, 3])}, float32. A missing piece is named."""
    import re

    path = Path(path)
    text = path.read_text()
    pieces = re.findall(r'<Piece Extent="(\d+) (\d+) [^"]*" Source="([^"]+)"/>', text)
    parts = []
    for first, stop, name in pieces:
        piece = path.parent / name
        if not piece.is_file():
            raise CaseFileError(f"{path}: its piece {name} (x-cells {first} .. {stop}) is missing")
        parts.append(read_vti(piece))
    return {name: np.concatenate([part[name] for part in parts]) for name in parts[0]}
