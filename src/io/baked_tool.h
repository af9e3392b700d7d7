// SPDX-License-Identifier: Apache-2.0
// Baked tools of stroke scripts (thesis 3.4.3): the level set or closed mesh a tool names,
// read and turned into a tool once. Tools are shared through a cache keyed by the file
// (and its modification time), the grid, the sampling and the band, so a study at several
// voxel sizes, an undo or a journal replay does not read a file twice.
#pragma once

#include <memory>
#include <string>

#include "levelset/interrupt.h"
#include "sculpt/stroke.h"
#include "tools/tool_shape.h"

namespace sweepers {

// The tool `source` names (a relative file is taken from `baseDir`), scaled by `size`, with
// a distance exact up to `reach` in the file's own units (the falloff divided by the
// smallest scale the tool is placed with). A mesh is sampled at source.voxelSize. Throws
// FileError or ScriptError saying what is wrong: a file that cannot be read, an open mesh,
// a shape with no inside, a band that would not fit in memory.
std::shared_ptr<const ToolShape> loadBakedTool(const BakedToolSource& source,
                                               const std::string& baseDir, double size,
                                               double reach, Interrupter* interrupter = nullptr);

// `file` as it is when absolute, else taken from `baseDir` ("" is the current directory).
std::string resolveAgainst(const std::string& file, const std::string& baseDir);

} // namespace sweepers
