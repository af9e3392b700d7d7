#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""A program's man page from its own --help and --version, by help2man.

man_page.py HELP2MAN PROGRAM SOURCE_DIR EXAMPLES GUIDES OUT

The programs are run in their build tree, where --help names the checkout's examples and
guides; the page names EXAMPLES and GUIDES instead, where the packages install them.
"""
import os
import subprocess
import sys
import tempfile

NAMES = {
    "sweepers": "sculpt narrow-band level sets by moving tools (the modeler)",
    "sweepers-cli": "apply stroke scripts, measure level sets, run grid-resolution studies",
}


def main():
    if len(sys.argv) != 7:
        sys.exit("usage: man_page.py HELP2MAN PROGRAM SOURCE_DIR EXAMPLES GUIDES OUT")
    help2man, program, source, examples, guides, out = sys.argv[1:]
    name = os.path.basename(program)
    see_also = (f"[SEE ALSO]\nThe guides, installed by sweepers-cli: {guides}/README.md and "
                f"{guides}/docs/ ({'modeler.md' if name == 'sweepers' else 'cli.md'}, "
                "stroke-scripts.md, studies.md, python.md, blender.md). The example stroke "
                f"scripts: {examples}.\n")
    with tempfile.NamedTemporaryFile("w", suffix=".h2m") as include:
        include.write(see_also)
        include.flush()
        page = subprocess.run([help2man, "--no-info", "--section=1", "--name", NAMES[name],
                               "--include", include.name, program],
                              check=True, capture_output=True, text=True).stdout
    page = page.replace(source.rstrip("/") + "/data", examples).replace(source.rstrip("/"), guides)
    if source in page:
        sys.exit(f"man_page.py: the page of {name} still names the checkout")
    with open(out, "w", encoding="utf-8") as f:
        f.write(page)


if __name__ == "__main__":
    main()
