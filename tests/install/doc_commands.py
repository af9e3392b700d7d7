#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The commands of the README and the guides, run as a reader pastes them, after an install.

doc_commands.py GUIDES BIN WORK [--coarse] [--python-path SITE]

GUIDES is where the installed README.md sits with docs/ beside it; BIN holds the installed
programs (put first on the PATH); each document runs in a folder of its own under WORK, its
commands one after another in one shell, so a variable it sets (ex=...) carries on as it
does for the reader.

What runs: every line of a code block whose command is `sweepers-cli` (or a one-line `for`
loop over it, or `ex=$(...)`) or `/usr/bin/python3`, and the Python blocks (the README's
indented one, the fenced ones of each guide, one interpreter a document). What does not, and
why:
- a block with an option in brackets: a synopsis, not a command;
- a command with `--slurm` or GNU `parallel -S`: it needs a cluster or hosts (the Slurm
  submission is tested on a real one-node cluster by cli.slurm);
- the developer's commands (`bash .ci/...`, `build/...`, `git ...`): they are for a checkout.
--coarse runs the same commands at coarse voxel sizes (`--voxel-size 0.0625` added to apply,
animate and check; `--voxel-sizes 1/16,1/32` for study), so CI can afford it.
"""
import glob
import os
import re
import subprocess
import sys

RUNNABLE = re.compile(r"^(?:[A-Z_]+=\S+\s+)*(sweepers-cli|/usr/bin/python3)\b"
                      r"|^ex=\$\(sweepers-cli examples\)|^for .*\bsweepers-cli\b")
NEEDS_A_CLUSTER = re.compile(r"--slurm\b|\bparallel -S\b")


def blocks(text):
    """(kind, [lines]) of each code block: 'indented' (four spaces) or a fence's language."""
    out, current, fence = [], None, None
    for line in text.splitlines() + [""]:
        if fence is not None:
            if line.startswith("```"):
                out.append((fence, current))
                fence, current = None, None
            else:
                current.append(line)
            continue
        if line.startswith("```"):
            if current:
                out.append(("indented", current))
            fence, current = line[3:].strip() or "text", []
        elif line.startswith("    ") and not line.lstrip().startswith(("- ", "* ", "|")):
            current = (current or []) + [line[4:]]
        else:
            if current:
                out.append(("indented", current))
            current = None
    return out


def commands(lines):
    """The lines of a shell block joined where they continue (a trailing \\ or |)."""
    joined, pending = [], ""
    for line in lines:
        pending += line.strip() + " "
        if line.rstrip().endswith(("\\", "|")):
            pending = pending.rstrip().rstrip("\\") + " "
            continue
        joined.append(pending.strip())
        pending = ""
    if pending.strip():
        joined.append(pending.strip())
    return joined


def coarse(command):
    """The same command at coarse voxel sizes."""
    command = re.sub(r"\s+#\s.*$", "", command)  # a trailing comment
    words = command.split()
    if len(words) < 2 or words[0] != "sweepers-cli":
        return command
    if words[1] == "study" and not re.search(r"\s-o \S+ --(list|run|merge)\b", command):
        command = re.sub(r"--voxel-sizes \S+", "", command) + " --voxel-sizes 1/16,1/32"
    elif words[1] in ("apply", "animate", "check") and "--voxel-size " not in command:
        command += " --voxel-size 0.0625"
    return command


def main():
    args = sys.argv[1:]
    coarse_sizes = "--coarse" in args
    site = None
    if "--python-path" in args:
        site = args[args.index("--python-path") + 1]
        args = [a for a in args if a not in ("--python-path", site)]
    args = [a for a in args if a != "--coarse"]
    if len(args) != 3:
        sys.exit("usage: doc_commands.py GUIDES BIN WORK [--coarse] [--python-path SITE]")
    guides, bin_dir, work = (os.path.abspath(a) for a in args)
    env = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ["PATH"])
    if site:
        env["PYTHONPATH"] = site
    env.setdefault("MPLBACKEND", "Agg")
    documents = [os.path.join(guides, "README.md")]
    documents += sorted(glob.glob(os.path.join(guides, "docs", "*.md")))
    ran = {}
    for document in documents:
        name = os.path.relpath(document, guides)
        shell, python = [], []
        with open(document, encoding="utf-8") as f:
            for kind, lines in blocks(f.read()):
                if kind == "python" or (kind == "indented" and lines[0].startswith("import ")):
                    python.append("\n".join(lines))
                    continue
                if kind not in ("indented", "sh", "bash", "shell") or any("[" in l for l in lines):
                    continue
                for command in commands(lines):
                    if RUNNABLE.match(command) and not NEEDS_A_CLUSTER.search(command):
                        shell.append(coarse(command) if coarse_sizes else command)
        folder = os.path.join(work, name.replace("/", "_").replace(".md", ""))
        os.makedirs(folder, exist_ok=True)
        runs = (("shell", ["bash", "-euo", "pipefail", "-c"], "\n".join(shell)),
                ("python", ["/usr/bin/python3", "-c"], "\n\n".join(python)))
        for what, program, text in runs:
            if not text:
                continue
            run_env = dict(env)
            runtime = os.environ.get("SWEEPERS_ASAN_RUNTIME")
            if runtime and what == "python":
                # The sanitizer build's module needs its runtime first; the programs carry theirs.
                run_env["LD_PRELOAD"] = runtime
                run_env["ASAN_OPTIONS"] = "detect_leaks=0"
            elif runtime:
                # The same for the interpreter the shell commands start (bash allows the name).
                text = (f"function /usr/bin/python3 {{ LD_PRELOAD={runtime} "
                        "ASAN_OPTIONS=detect_leaks=0 command /usr/bin/python3 \"$@\"; }\n") + text
            done = subprocess.run(program + [text], cwd=folder, env=run_env,
                                  capture_output=True, text=True)
            if done.returncode != 0:
                sys.exit(f"FAIL: {name}'s {what} commands stopped (exit {done.returncode}):\n"
                         f"{text}\n--- stdout\n{done.stdout[-2000:]}\n"
                         f"--- stderr\n{done.stderr[-3000:]}")
        ran[name] = (len(shell), len(python))
        print(f"{name}: {len(shell)} shell commands, {len(python)} Python blocks ran")
    # What the guides are known to hold, so that a change that stops finding them fails here.
    if ran.get("README.md", (0, 0))[0] < 8 or ran["README.md"][1] < 1:
        sys.exit(f"FAIL: the README's commands were not found: {ran.get('README.md')}")
    if ran.get("docs/python.md", (0, 0))[1] < 6 or ran.get("docs/studies.md", (0, 0))[0] < 5:
        sys.exit(f"FAIL: the guides' commands were not found: {ran}")


if __name__ == "__main__":
    main()
