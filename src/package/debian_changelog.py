#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Debian's changelog of the packages, from CHANGELOG.md's released sections.

debian_changelog.py CHANGELOG.md VERSION MAINTAINER OUT

Each "## X.Y.Z (... DATE)" section becomes one entry, its bullets the entry's items; the
section of the version being packaged gets the packaging revision VERSION names (0.2.0-1),
older ones -1. Changes not yet released are in the upstream CHANGELOG.md the packages also
install, not here: Debian's changelog lists versions that exist.
"""
import datetime
import re
import sys
import textwrap


def sections(text):
    """(version, last date, [item texts]) for each released section, newest first."""
    out = []
    current = None
    for line in text.splitlines():
        head = re.match(r"^## (\d+\.\d+\.\d+) \((.*)\)\s*$", line)
        if head:
            dates = re.findall(r"\d{4}-\d{2}-\d{2}", head.group(2))
            if not dates:
                sys.exit(f"debian_changelog: section {head.group(1)} names no date")
            current = (head.group(1), dates[-1], [])
            out.append(current)
        elif line.startswith("## "):
            current = None  # Unreleased, or any other heading
        elif current is not None and line.startswith("- "):
            current[2].append(line[2:].strip())
        elif current is not None and line.startswith("  ") and current[2]:
            current[2][-1] += " " + line.strip()
    return out


def entry(version, date, items, maintainer):
    day = datetime.datetime.strptime(date, "%Y-%m-%d").replace(tzinfo=datetime.timezone.utc)
    lines = [f"sweepers ({version}) bookworm; urgency=medium", ""]
    for item in items:
        plain = item.replace("**", "")
        lines += textwrap.wrap(plain, width=78, initial_indent="  * ", subsequent_indent="    ",
                               break_on_hyphens=False)
    lines += ["", f" -- {maintainer}  {day.strftime('%a, %d %b %Y %H:%M:%S +0000')}", ""]
    return "\n".join(lines)


def main():
    if len(sys.argv) != 5:
        sys.exit("usage: debian_changelog.py CHANGELOG.md VERSION MAINTAINER OUT")
    changelog, version, maintainer, out = sys.argv[1:]
    with open(changelog, encoding="utf-8") as f:
        released = sections(f.read())
    upstream = version.split("-")[0]
    if not any(v == upstream for v, _, _ in released):
        sys.exit(f"debian_changelog: CHANGELOG.md has no section for {upstream}")
    entries = []
    for v, date, items in released:
        if not items:
            sys.exit(f"debian_changelog: section {v} lists no change")
        entries.append(entry(version if v == upstream else v + "-1", date, items, maintainer))
    with open(out, "w", encoding="utf-8") as f:
        f.write("\n".join(entries))


if __name__ == "__main__":
    main()
