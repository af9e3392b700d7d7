#include "io/film_files.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>

#include <nlohmann/json.hpp>
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

std::vector<std::string> frameDigests(const std::string& scriptText, const StrokeScript& script,
                                      const FilmTiming& timing, const std::string& extra) {
    const std::vector<double> durations = strokeDurations(script, timing);
    double seconds = 0.0;
    for (double d : durations)
        seconds += d;
    const std::size_t count = filmFrameCount(seconds, timing.fps);
    nlohmann::json header = nlohmann::json::parse(scriptText);
    const nlohmann::json strokes = header.at("strokes");
    header.erase("strokes");
    // A keyed stroke with only the keys given (their places in the list kept).
    auto withKeys = [](nlohmann::json stroke, const std::vector<std::size_t>& which) {
        nlohmann::json kept = nlohmann::json::array();
        for (std::size_t k : which)
            kept.push_back({{"key", k}, {"is", stroke["keys"][k]}});
        stroke["keys"] = kept;
        return stroke;
    };
    // The keys that shape a keyed stroke's spline at time u in it: on the piece between
    // keys i and i + 1, the tangents at both ends reach keys i - 1 and i + 2 (at the last
    // key's time, the last piece's).
    auto keysAt = [](const nlohmann::json& stroke, double u) {
        const nlohmann::json& keys = stroke["keys"];
        const std::size_t n = keys.size();
        std::size_t i = 0;
        while (i + 2 < n && keys[i + 1].at("time").get<double>() <= u)
            ++i;
        std::vector<std::size_t> which{0};
        if (u <= 0.0) return which;
        for (std::size_t k = i == 0 ? 1 : i - 1; k <= std::min(n - 1, i + 2); ++k)
            which.push_back(k);
        return which;
    };
    std::vector<std::string> digests(count + 1);
    char number[40];
    for (std::size_t n = 1; n <= count; ++n) {
        const double time = filmFrameTime(n, seconds, timing.fps);
        std::snprintf(number, sizeof number, "%.17g", time);
        std::string made = header.dump() + "\n" + extra + "\n" + number + "\n";
        double start = 0.0;
        for (std::size_t i = 0; i < strokes.size(); ++i) {
            const double end = start + durations[i];
            const bool keyed = keyedDuration(script.strokes[i]) > 0.0;
            // The film adds up its strokes' times its own way: a frame within a hair of a
            // stroke's end counts as in it, with every key that can reach there.
            const bool atEnd = std::abs(time - end) <= 1e-9 * std::max(1.0, end);
            std::snprintf(number, sizeof number, " for %.17g", durations[i]);
            if (time < end || atEnd) {
                const double u = std::min(time, end) - start;
                made += (keyed ? withKeys(strokes[i], keysAt(strokes[i], u)) : strokes[i]).dump() +
                        number;
                std::snprintf(number, sizeof number, " at %.17g\n", u);
                made += number;
                if (time < end) break;
            } else {
                made +=
                    (keyed ? withKeys(strokes[i], {0, strokes[i]["keys"].size() - 1}) : strokes[i])
                        .dump() +
                    number + "\n";
            }
            start = end;
        }
        digests[n] = scriptDigest(made);
    }
    return digests;
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
