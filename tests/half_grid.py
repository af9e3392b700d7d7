# SPDX-License-Identifier: Apache-2.0
"""half_grid.py FULL.vdb HALF.vdb: HALF is FULL written with 16-bit float values: a float
level set that says so in its metadata (every grid of its file), holding the same active
voxels, each value rounded by at most 1/2048 of itself or, near the surface, of a voxel,
and by something somewhere. Importable: rounding(full_path, half_path)."""
import sys

import pyopenvdb as vdb


def rounding(full_path, half_path):
    """The largest rounding, as a fraction of max(|value|, voxel size), after the checks."""
    grids, _ = vdb.readAll(half_path)
    assert all(g.metadata.get("is_saved_as_half_float") is True for g in grids), \
        [g.metadata for g in grids]
    half = next(g for g in grids if g.name == "surface")
    full = vdb.read(full_path, "surface")
    assert not full.metadata.get("is_saved_as_half_float", False), full.metadata
    assert half.gridClass == vdb.GridClass.LEVEL_SET and half.valueTypeName == "float"
    h = full.transform.voxelSize()[0]
    a = {it.min: it.value for it in full.citerOnValues() if it.count == 1}
    b = {it.min: it.value for it in half.citerOnValues() if it.count == 1}
    assert a.keys() == b.keys(), "the active voxels differ"
    worst = max(abs(b[k] - v) / max(abs(v), h) for k, v in a.items())
    assert 0 < worst <= 1 / 2048, worst
    return worst


if __name__ == "__main__":
    print(f"half floats: largest rounding {rounding(*sys.argv[1:3]) * 2048:.2f}/2048")
