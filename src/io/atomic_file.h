// Atomic saves: the content is written to a temporary file next to the target, flushed to
// disk and renamed over the target, so a crash or an error never leaves a half-written
// file and never destroys the previous version.
#pragma once

#include <functional>
#include <string>

namespace sweepers {

// Calls write(tmpPath) to produce the content, then fsyncs and renames it to `path`.
// On any failure the temporary file is removed and std::runtime_error says why.
void writeFileAtomically(const std::string& path,
                         const std::function<void(const std::string& tmpPath)>& write);

// Convenience for text content.
void writeTextAtomically(const std::string& path, const std::string& text);

// The directory part of a path ("." when there is none).
std::string directoryOf(const std::string& path);

} // namespace sweepers
