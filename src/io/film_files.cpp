// SPDX-License-Identifier: Apache-2.0
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

namespace {

// 64-bit FNV-1a, fed piece by piece: a digest of what came so far can be copied and fed on.
class Fnv {
  public:
    void add(const std::string& text) {
        for (const unsigned char c : text) {
            h_ ^= c;
            h_ *= 1099511628211ull;
        }
    }
    std::string hex() const {
        char hex[17];
        std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h_));
        return hex;
    }

  private:
    std::uint64_t h_ = 14695981039346656037ull;
};

std::string decimal(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", v);
    return text;
}

} // namespace

std::string scriptDigest(const std::string& text) {
    Fnv f;
    f.add(text);
    return f.hex();
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
    auto keyed = [&](std::size_t i) { return keyedDuration(script.strokes[i]) > 0.0; };
    std::vector<double> ends;
    ends.reserve(durations.size());
    for (double d : durations)
        ends.push_back((ends.empty() ? 0.0 : ends.back()) + d);
    // The film adds up its strokes' times its own way: a frame within a hair of a stroke's
    // end counts as in it, with every key that can reach there, and in the next.
    auto atEnd = [&](double time, std::size_t i) {
        return std::abs(time - ends[i]) <= 1e-9 * std::max(1.0, ends[i]);
    };
    // What every frame from here on is made of: the script's grid and start, `extra`, and
    // the strokes finished before the frame (a keyed one by its first and last key). The
    // frames come in time order, so the finished strokes are added once each.
    Fnv finished;
    finished.add(header.dump() + "\n" + extra + "\n");
    std::size_t done = 0;
    std::vector<std::string> digests(count + 1);
    for (std::size_t n = 1; n <= count; ++n) {
        const double time = filmFrameTime(n, seconds, timing.fps);
        for (; done < strokes.size() && time > ends[done] && !atEnd(time, done); ++done)
            finished.add((keyed(done)
                              ? withKeys(strokes[done], {0, strokes[done]["keys"].size() - 1})
                              : strokes[done])
                             .dump() +
                         " for " + decimal(durations[done]) + "\n");
        // The stroke the frame falls in, and the time in it.
        Fnv made = finished;
        for (std::size_t i = done; i < strokes.size(); ++i) {
            const double start = i == 0 ? 0.0 : ends[i - 1];
            const double u = std::min(time, ends[i]) - start;
            made.add((keyed(i) ? withKeys(strokes[i], keysAt(strokes[i], u)) : strokes[i]).dump() +
                     " for " + decimal(durations[i]) + " at " + decimal(u) + "\n");
            if (time < ends[i]) break;
        }
        made.add("frame at " + decimal(time));
        digests[n] = made.hex();
    }
    return digests;
}

AtomicWrite prepareFrame(const Grid& grid, const FrameStamp& stamp, const std::string& path,
                         const FrameFileOptions& options) {
    LevelSetWriteOptions write;
    write.half = options.half;
    write.meta.insertMeta("frame", openvdb::Int32Metadata(stamp.frame));
    write.meta.insertMeta("time", openvdb::DoubleMetadata(stamp.time));
    write.meta.insertMeta("fps", openvdb::DoubleMetadata(stamp.fps));
    write.meta.insertMeta("script", openvdb::StringMetadata(stamp.script));
    if (!options.fog.empty()) {
        GridPtr fog = grid.deepCopy();
        openvdb::tools::sdfToFogVolume(*fog);
        fog->setName(options.fog);
        for (auto it = write.meta.beginMeta(); it != write.meta.endMeta(); ++it)
            fog->insertMeta(it->first, *it->second);
        fog->setSaveFloatAsHalf(options.half);
        write.beside.push_back(fog);
    }
    return prepareLevelSet(grid, path, write);
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
