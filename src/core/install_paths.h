// SPDX-License-Identifier: Apache-2.0
// Where the running program's examples and guides are, for its --help: installed beside it
// (PREFIX/bin -> PREFIX/share/sweepers/examples, PREFIX/share/doc/sweepers), or for a
// program in the build tree it was built in, the checkout's data/ and its README and docs/.
#pragma once

#include <string>

namespace sweepers {

struct ProgramPlaces {
    std::string examples; // the stroke scripts (and the files they name)
    std::string guides;   // README.md, with the guides in docs/ beside it
};
ProgramPlaces programPlaces();

} // namespace sweepers
