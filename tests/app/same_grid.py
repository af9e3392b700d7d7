# SPDX-License-Identifier: Apache-2.0
"""same_grid.py A.vdb B.vdb: the two level sets hold the same voxels (values and states)."""
import sys
import pyopenvdb as vdb

a = vdb.read(sys.argv[1], "surface")
b = vdb.read(sys.argv[2], "surface")
aa, ba = a.getConstAccessor(), b.getConstAccessor()
assert a.activeVoxelCount() == b.activeVoxelCount(), (a.activeVoxelCount(), b.activeVoxelCount())
differ = 0
for grid, other in ((a, ba), (b, aa)):
    for it in grid.citerOnValues():
        if it.count != 1:
            continue
        value, on = other.probeValue(it.min)
        differ += value != it.value or not on
assert differ == 0, f"{differ} voxels differ"
print(f"same grid: {a.activeVoxelCount()} active voxels")
