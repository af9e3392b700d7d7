// SPDX-License-Identifier: Apache-2.0
// cli/slurm.h: the job scripts and requests a study's submission makes, from its plan alone
// (the real cluster's test is tests/cli/slurm.sh).
#include <array>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "cli/slurm.h"
#include "scratch_dir.h"

using namespace sweepers;

namespace {

PlannedRun run(const std::string& id, double h, double memoryMb, double seconds) {
    PlannedRun r;
    r.id = id;
    r.voxelSize = h;
    r.memoryMb = memoryMb;
    r.seconds = seconds;
    return r;
}

// What bash prints running `script` with the environment `env` before it.
std::string bashOutput(const std::string& env, const std::string& script) {
    std::string out;
    const std::unique_ptr<FILE, int (*)(FILE*)> pipe(
        ::popen((env + " bash '" + script + "' 2>&1").c_str(), "r"), ::pclose);
    std::array<char, 256> buffer;
    while (pipe && std::fgets(buffer.data(), int(buffer.size()), pipe.get()))
        out += buffer.data();
    return out;
}

} // namespace

// Three runs at two voxel sizes: one array per size, coarsest first, each asking for its
// largest run's memory (1.5 x the estimate + 256 MB) and time (2 x + 5 minutes, none where
// nothing is known), the throttle and the user's directives on every job; the job script
// runs the run its task names, with a directory whose name needs quoting.
TEST(Slurm, TheScriptsAskForEachVoxelSizesLargestRun) {
    const test::ScratchDir dir;
    StudyPlan plan;
    plan.dir = dir / "it's a study";
    plan.runs = {run("poke-corrected_32", 1.0 / 32, 100, 60),
                 run("poke-trilinear_32", 1.0 / 32, 200, 0),
                 run("poke-corrected_64", 1.0 / 64, 800, 600)};
    cli::SlurmOptions options;
    options.maxRunning = 2;
    options.cpusPerTask = 4;
    options.partition = "short";
    options.account = "lab";
    options.sbatchArgs = {"--qos=low"};
    const cli::SlurmScripts s = cli::slurmScripts(plan, {0, 1, 2}, options, "/bin/echo");

    ASSERT_EQ(s.arrays.size(), 2u);
    EXPECT_EQ(s.arrays[0].voxelSize, 1.0 / 32);
    EXPECT_EQ(s.arrays[0].runs, (std::vector<std::size_t>{0, 1}));
    EXPECT_EQ(s.arrays[0].memoryMb, 556); // 200 x 1.5 + 256
    EXPECT_EQ(s.arrays[0].minutes, 7);    // 60 s x 2 + 5 minutes
    EXPECT_EQ(s.arrays[0].args,
              (std::vector<std::string>{"--array=0,1%2", "--mem=556M", "--time=7"}));
    EXPECT_EQ(s.arrays[1].runs, (std::vector<std::size_t>{2}));
    EXPECT_EQ(s.arrays[1].args,
              (std::vector<std::string>{"--array=2%2", "--mem=1456M", "--time=25"}));

    for (const std::string& line : std::vector<std::string>{
             "#SBATCH --array=0,1,2%2\n", "#SBATCH --mem=1456M\n", "#SBATCH --time=25\n",
             "#SBATCH --cpus-per-task=4\n", "#SBATCH --partition=short\n",
             "#SBATCH --account=lab\n", "#SBATCH --qos=low\n",
             "#SBATCH --output=" + plan.dir + "/slurm/logs/%A_%a.out\n"})
        EXPECT_NE(s.runs.find(line), std::string::npos) << line << " in\n" << s.runs;
    for (const std::string& line :
         std::vector<std::string>{"#SBATCH --mem=1024M\n", "#SBATCH --time=15\n",
                                  "#SBATCH --partition=short\n", "#SBATCH --qos=low\n"})
        EXPECT_NE(s.merge.find(line), std::string::npos) << line << " in\n" << s.merge;

    // Run as Slurm runs a task (the program here only echoes what it is given).
    std::ofstream(dir / "runs.sbatch") << s.runs;
    EXPECT_EQ(bashOutput("SLURM_ARRAY_TASK_ID=1 SLURM_CPUS_PER_TASK=4", dir / "runs.sbatch"),
              "study -o " + plan.dir + " --run poke-trilinear_32 --threads 4\n");
    std::ofstream(dir / "merge.sbatch") << s.merge;
    EXPECT_EQ(bashOutput("", dir / "merge.sbatch"), "study -o " + plan.dir + " --merge\n");

    // Only the runs still pending, without a throttle: the finer array alone.
    options.maxRunning = 0;
    const cli::SlurmScripts rest = cli::slurmScripts(plan, {2}, options, "/bin/echo");
    ASSERT_EQ(rest.arrays.size(), 1u);
    EXPECT_EQ(rest.arrays[0].args[0], "--array=2");
    EXPECT_NE(rest.runs.find("#SBATCH --array=2\n"), std::string::npos);
}
