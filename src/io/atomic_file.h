// SPDX-License-Identifier: Apache-2.0
// Atomic saves: the content is written to a temporary file next to the target, flushed to
// disk and renamed over the target, so a crash, a full disk or any other error never
// leaves a half-written file and never destroys the previous version.
//
// Every step is checked on the file's own descriptor: each write, the fsync, the close and
// the rename. Third-party writers (OpenVDB, Assimp) write into a stream whose buffer does
// those checked writes, because they do not all report a failed write themselves.
#pragma once

#include <functional>
#include <iosfwd>
#include <string>

namespace sweepers {

// A save in two steps, so that several files can be written before any replaces its old
// version: the constructor calls write(out) with a binary stream onto a temporary file
// beside `path` and fsyncs it; commit() renames it over `path`. On any failure the
// temporary file is removed, `path` is left as it was and std::runtime_error says why in one
// line ("PATH: cannot write: No space left on device"); a save never committed removes its
// temporary file. Temporary files that runs killed before their rename left beside `path`
// are removed first.
class AtomicWrite {
  public:
    AtomicWrite(const std::string& path, const std::function<void(std::ostream& out)>& write);
    AtomicWrite(AtomicWrite&& other) noexcept;
    AtomicWrite& operator=(AtomicWrite&&) = delete;
    AtomicWrite(const AtomicWrite&) = delete;
    AtomicWrite& operator=(const AtomicWrite&) = delete;
    ~AtomicWrite();
    void commit();

  private:
    std::string path_, tmp_; // tmp_ is empty once committed or moved from
};

// Both steps at once.
void writeFileAtomically(const std::string& path,
                         const std::function<void(std::ostream& out)>& write);

// Convenience for text content.
void writeTextAtomically(const std::string& path, const std::string& text);

// The directory part of a path ("." when there is none).
std::string directoryOf(const std::string& path);

} // namespace sweepers
