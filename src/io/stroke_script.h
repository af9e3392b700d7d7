// SPDX-License-Identifier: Apache-2.0
// Stroke scripts: the JSON file format of the stroke model (sculpt/stroke.h);
// docs/stroke-scripts.md documents every field.
//
//   { "sweepers": 1,
//     "grid":  { "voxel_size": 0.02, "half_width": 3 },
//     "start": { "sphere": { "center": [0,0,0], "radius": 1 } }   | {"vdb": F} | {"mesh": F}
//     "strokes": [ { "type": "sweep", "mirror": "x", "tools": [ {shape, size, falloff, path} ] },
//                  (shape: "ball" | "ellipsoid" | {"vdb": F, "grid": N} | {"mesh": F})
//                  { "type": "swirl", "at": [..], "move": [..], "radius": r,
//                    "ring": "discrete" | "convolution", "swirls": 8, "ball": rho },
//                  { "type": "inflate", "at": [..], "radius": rho },
//                  { "type": "flow", "field": "enright" | {"vdb": F, "grid": N} | ...,
//                    "from": t0, "to": t1, "segments": n },
//                  { "type": "fluid", "radius": r, "path": [[..], [..]] } ] }
//     (and pinch, strangle, keyframed, slide: docs/stroke-scripts.md documents every field)
//     (any stroke may add "duration": seconds, for films: sculpt/film.h)
//
// Reading validates everything, including that every segment's motion has a logarithm,
// and refuses the whole script on the first problem with a ScriptError whose message
// names the file, the JSON location (a JSON pointer) and the reason. Unknown fields are
// refused too: in a hand-written script they are nearly always typos.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sculpt/stroke.h"

namespace sweepers {

class ScriptError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// Parse and validate, touching no disk: a script is data. `name` is used in messages
// (usually the file path). The files it names (a VDB or mesh start, baked tools, sampled
// velocity fields) are kept as written, and what they hold, like the swept fluid's
// solution, is left for loadScriptInputs; so are the checks that need it (a baked tool's
// sub-steps, a sampled field's speed).
StrokeScript parseStrokeScript(const std::string& text, const std::string& name);
// Resolves what a parsed script reads (but its start, which io/start_grid.h builds): baked
// tools' and velocity fields' files (relative names from `baseDir`, "" for the current
// directory) and the swept fluid (io/fluid_cache.h). A tool or field that cannot be made
// refuses the script as a parsing mistake does, at its JSON location. What is already loaded
// is kept.
void loadScriptInputs(StrokeScript& script, const std::string& name,
                      const std::string& baseDir = "");
// Both: a script ready to apply.
StrokeScript loadStrokeScript(const std::string& text, const std::string& name,
                              const std::string& baseDir = "");
// Read a file, parse it and load its inputs (relative to it); a missing or unreadable file
// is a ScriptError too. `text`, if given, receives the file's text as it was parsed.
StrokeScript readStrokeScript(const std::string& path, std::string* text = nullptr);

// Every field name a script may hold, in any object: the parser refuses all others, and the
// reference, docs/stroke-scripts.md, must name each.
std::vector<std::string> strokeScriptFields();
// Serialize (numbers round-trip exactly): pretty-printed with `indent` spaces and a final
// line break, or on one line without a line break when indent < 0.
std::string formatStrokeScript(const StrokeScript& script, int indent = 2);
// Calls `visit` with every file name the script refers to (its start, baked tools and
// sampled velocity fields, as written in it), which it may change.
void forEachScriptFile(StrokeScript& script, const std::function<void(std::string& file)>& visit);
// The same script with its start and tool files named absolutely (relative names are taken
// from `scriptDir`), so that it works wherever it is saved.
StrokeScript withAbsoluteFiles(StrokeScript script, const std::string& scriptDir);
// Write atomically: temporary file beside the target, flush, rename.
void writeStrokeScript(const StrokeScript& script, const std::string& path);

} // namespace sweepers
