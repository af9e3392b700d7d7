// SPDX-License-Identifier: Apache-2.0
#include "io/fluid_cache.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <tuple>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include "core/format.h"
#include "core/stopwatch.h"
#include "io/isolated_read.h"
#include "io/velocity_file.h"

namespace sweepers {

namespace {

// Bumped when the solver changes what it computes, so older cache files are solved again.
// 3: the lattice's size kept with it (velocity_file.h), so that a run that reads the cache
// makes the field of the same lattice as the run that solved it.
constexpr int kSolverVersion = 3; // 2: the exact solves of the diffusion and the pressure

std::string cacheDirectory() {
    if (const char* d = std::getenv("SWEEPERS_CACHE"); d && *d) return d;
    if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return std::string(d) + "/sweepers";
    if (const char* d = std::getenv("HOME"); d && *d) return std::string(d) + "/.cache/sweepers";
    return "";
}

openvdb::MetaMap describe(const FluidSpec& spec) {
    openvdb::MetaMap meta;
    meta.insertMeta("fluid_solver_version", openvdb::Int32Metadata(kSolverVersion));
    meta.insertMeta("fluid_cells", openvdb::Int32Metadata(spec.cells));
    meta.insertMeta("fluid_ball_radius", openvdb::DoubleMetadata(spec.ballRadius));
    meta.insertMeta("fluid_viscosity", openvdb::DoubleMetadata(spec.viscosity));
    meta.insertMeta("fluid_time_step", openvdb::DoubleMetadata(spec.timeStep));
    return meta;
}

// Whether the cached grid was solved with `spec` by this solver.
bool solvedWith(const openvdb::GridBase& grid, const FluidSpec& spec) {
    const openvdb::MetaMap want = describe(spec);
    for (auto it = want.beginMeta(); it != want.endMeta(); ++it) {
        const openvdb::Metadata::ConstPtr have = grid[it->first];
        if (!have || have->str() != it->second->str()) return false;
    }
    return true;
}

} // namespace

std::string fluidCachePath(const FluidSpec& spec) {
    const std::string dir = cacheDirectory();
    const std::string name = "swept_fluid_" + std::to_string(spec.cells) + "_r" +
                             formatNumber(spec.ballRadius) + "_nu" + formatNumber(spec.viscosity) +
                             "_dt" + formatNumber(spec.timeStep) + ".vdb";
    return dir.empty() ? name : dir + "/" + name;
}

std::shared_ptr<const SweptFluid> sweptFluid(const FluidSpec& spec, std::string* said) {
    static std::mutex lock;
    static std::map<std::tuple<int, double, double, double>, std::shared_ptr<const SweptFluid>>
        solved;
    const std::lock_guard<std::mutex> hold(lock);
    const auto key = std::make_tuple(spec.cells, spec.ballRadius, spec.viscosity, spec.timeStep);
    if (auto it = solved.find(key); it != solved.end()) {
        if (said) *said = "the swept fluid was found earlier in this run";
        return it->second;
    }
    const std::string path = fluidCachePath(spec);
    // Processes that want the same solution at once (tests in parallel, two modelers) take
    // turns: the first solves, the others wait and read what it kept.
    std::error_code made;
    std::filesystem::create_directories(std::filesystem::path(path).parent_path(), made);
    const int lockFd = ::open((path + ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (lockFd >= 0) ::flock(lockFd, LOCK_EX);
    struct Unlock {
        int fd;
        ~Unlock() {
            if (fd >= 0) ::close(fd); // releases the lock
        }
    } unlock{lockFd};
    std::string note;
    std::shared_ptr<const SweptFluid> fluid;
    std::error_code ec;
    if (std::filesystem::exists(path, ec)) {
        try {
            const VelocityFile file = readVelocityInChild(path, "velocity");
            if (solvedWith(*file.grid, spec)) {
                fluid = std::make_shared<SweptFluid>(velocitySamples(file, path), spec.ballRadius);
                note = "read the swept fluid from " + path;
            } else {
                note = path + " was solved with other parameters; ";
            }
        } catch (const std::exception& e) {
            note = std::string(e.what()) + "; ";
        }
    }
    if (!fluid) {
        const auto start = Clock::now();
        const FluidSolution solution = solveSweptFluid(spec);
        // The samples as the cache gives them back, so that this run and the runs that read
        // them sculpt the same grid, to the bit.
        fluid = std::make_shared<SweptFluid>(storedSamples(solution.samples), spec.ballRadius);
        note += "solved the swept fluid (" + std::to_string(spec.cells) + "^3 cells) in " +
                formatNumber(std::round(secondsSince(start) * 10.0) / 10.0) + " s";
        try {
            writeVelocity(solution.samples, path, "velocity", describe(spec));
            note += " and kept it in " + path;
        } catch (const std::exception& e) {
            note += "; could not keep it (" + std::string(e.what()) + ")";
        }
    }
    if (said) *said = note;
    solved.emplace(key, fluid);
    return fluid;
}

} // namespace sweepers
