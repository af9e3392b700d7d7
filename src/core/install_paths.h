// SPDX-License-Identifier: Apache-2.0
// Where the running program's examples and guides are, for its --help and for
// `sweepers-cli examples`: installed beside it (PREFIX/bin -> PREFIX/share/sweepers/examples,
// PREFIX/share/doc/sweepers-cli), or for a program in the build tree it was built in, the
// checkout's data/ and its README and docs/.
#pragma once

#include <string>

namespace sweepers {

struct ProgramPlaces {
    std::string examples; // the stroke scripts (and the files they name)
    std::string guides;   // README.md, with the guides in docs/ beside it
};
// For the running program (PREFIX/bin/NAME).
ProgramPlaces programPlaces();
// For the Python module at `moduleFile` (PREFIX/lib/python3/dist-packages/NAME.so, or a
// versioned lib/python3.X/{dist,site}-packages).
ProgramPlaces modulePlaces(const std::string& moduleFile);

} // namespace sweepers
