// SPDX-License-Identifier: Apache-2.0
// Reading level-set and velocity files we did not write in a child process. OpenVDB's reader can
// crash, loop or allocate without bound on a damaged file; in a child with a time and a
// memory limit the worst it can do is end that child, and the caller gets a FileError in
// one line while its own work (a modeler session) goes on.
//
// The child is this same executable, started again with a marker argument: a static
// initializer of this module sees the marker before main() runs, reads the file with the
// in-process reader, sends the validated grid back through a pipe in OpenVDB's stream
// format (which the parent reads safely: we wrote it) and exits. Every executable that
// links the io layer can therefore serve as its own reader, tests included.
#pragma once

#include <string>
#include <vector>

#include "io/vdb_file.h"
#include "io/velocity_file.h"

namespace sweepers {

struct ReadLimits {
    double seconds = 120.0; // wall clock for the whole read
    double bytes = 0.0;     // address space of the child; 0: 64 times the file, at least
                            // 512 MB, at most the memory available
};

// The command that starts a reader, before the marker and its arguments: by default this
// executable. A host whose executable is not ours (the Python module, in an interpreter)
// names one that loads this layer, such as {python3, -c, "import sweepers"}.
void setReaderCommand(std::vector<std::string> command);

// readLevelSetInProcess(path, gridName) (io/vdb_file.h) in a child process. Throws FileError with
// the child's own message when it refuses the file, or saying that the file is damaged
// when the child crashed, ran out of time or of memory.
LevelSetFile readLevelSetInChild(const std::string& path, const std::string& gridName = "",
                                 const ReadLimits& limits = {});
// readVelocityInProcess(path, gridName) (io/velocity_file.h) in a child process, the same way.
VelocityFile readVelocityInChild(const std::string& path, const std::string& gridName = "",
                                 const ReadLimits& limits = {});

} // namespace sweepers
