#include "io/film_files.h"

#include <cstdint>
#include <cstdio>
#include <stdexcept>

#include <openvdb/tools/LevelSetUtil.h>

#include "io/vdb_file.h"

namespace sweepers {

void checkFramePattern(const std::string& pattern) {
    const std::size_t at = pattern.find('#');
    if (at == std::string::npos)
        throw std::invalid_argument(pattern + ": a frame pattern needs a run of '#' for the "
                                              "frame number (for example frames/shape_####.vdb)");
    const std::size_t end = pattern.find_first_not_of('#', at);
    if (end != std::string::npos && pattern.find('#', end) != std::string::npos)
        throw std::invalid_argument(pattern + ": a frame pattern holds one run of '#', not two");
}

std::string framePath(const std::string& pattern, std::size_t frame) {
    checkFramePattern(pattern);
    const std::size_t at = pattern.find('#');
    const std::size_t end = std::min(pattern.find_first_not_of('#', at), pattern.size());
    std::string digits = std::to_string(frame);
    if (digits.size() < end - at) digits.insert(0, end - at - digits.size(), '0');
    return pattern.substr(0, at) + digits + pattern.substr(end);
}

std::string scriptDigest(const std::string& text) {
    std::uint64_t h = 14695981039346656037ull;
    for (const unsigned char c : text) {
        h ^= c;
        h *= 1099511628211ull;
    }
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
    return hex;
}

AtomicWrite prepareFrame(const Grid& grid, const FrameStamp& stamp, const std::string& fogName,
                         const std::string& path) {
    openvdb::MetaMap meta;
    meta.insertMeta("frame", openvdb::Int32Metadata(stamp.frame));
    meta.insertMeta("time", openvdb::DoubleMetadata(stamp.time));
    meta.insertMeta("fps", openvdb::DoubleMetadata(stamp.fps));
    meta.insertMeta("script", openvdb::StringMetadata(stamp.script));
    openvdb::GridCPtrVec beside;
    if (!fogName.empty()) {
        GridPtr fog = grid.deepCopy();
        openvdb::tools::sdfToFogVolume(*fog);
        fog->setName(fogName);
        for (auto it = meta.beginMeta(); it != meta.endMeta(); ++it)
            fog->insertMeta(it->first, *it->second);
        beside.push_back(fog);
    }
    return prepareLevelSet(grid, path, meta, beside);
}

std::optional<FrameStamp> readFrameStamp(const std::string& path) {
    GridPtr grid;
    try {
        grid = readLevelSet(path);
    } catch (const FileError&) {
        return std::nullopt;
    }
    const auto frame = grid->getMetadata<openvdb::Int32Metadata>("frame");
    const auto time = grid->getMetadata<openvdb::DoubleMetadata>("time");
    const auto fps = grid->getMetadata<openvdb::DoubleMetadata>("fps");
    const auto script = grid->getMetadata<openvdb::StringMetadata>("script");
    if (!frame || !time || !fps || !script) return std::nullopt;
    return FrameStamp{frame->value(), time->value(), fps->value(), script->value(),
                      grid->voxelSize()[0]};
}

} // namespace sweepers
