"""Uniform-grid fields as VTK XML ImageData (``.vti``), which ParaView opens directly.

Cell data only (the fluid's cell-centred fields). Arrays are stored as float32 (enough for
pictures; the checkpoint keeps float64), zlib-compressed, appended raw after the XML header
(``header_type="UInt64"``), each as one compressed block: header [1, raw size, raw size,
compressed size] then the bytes. VTK orders cells with x fastest, so riprap's [i, j, k] arrays are
written in Fortran order. The file is written to a temporary name and moved into place.
"""
from __future__ import annotations

import os
import zlib
from pathlib import Path

import numpy as np

from riprap.errors import CaseFileError
from riprap.io.output_folder import naming_the_file

__all__ = ["write_vti", "read_vti"]


def _block(array: np.ndarray) -> bytes:
    raw = np.ascontiguousarray(array).tobytes()
    packed = zlib.compress(raw, 1)
    return np.array([1, len(raw), len(raw), len(packed)], dtype="<u8").tobytes() + packed


def write_vti(path, *, origin, spacing: float, cells, cell_data) -> Path:
    """Write ``cell_data`` (name -> array of shape ``cells`` or ``cells + (3,)``) on the grid of
    ``cells`` = (nx, ny, nz) cubes of side ``spacing`` from ``origin`` (m)."""
    path = Path(path)
    nx, ny, nz = (int(n) for n in cells)
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
    extent = f"0 {nx} 0 {ny} 0 {nz}"
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
    nx, ny, nz = (int(v) for v in re.search(r'WholeExtent="0 (\d+) 0 (\d+) 0 (\d+)"', text).groups())
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
