#!/usr/bin/env python3
"""long_functions.py [LIMIT] [FOLDERS...]: functions longer than LIMIT lines (default 120) in the C++
sources under FOLDERS (default baker runtime), tests (*_test.cpp) left out. Lengths come from
Universal Ctags (`ctags --fields=+ne`: a function's first and last line; lambdas are counted inside
their function, not on their own). Prints "lines file:line name", longest first; exit 1 if any."""
import json
import subprocess
import sys


def main():
    args = sys.argv[1:]
    limit = int(args.pop(0)) if args and args[0].isdigit() else 120
    folders = args or ["baker", "runtime"]
    out = subprocess.run(["ctags", "-R", "--languages=C++", "--kinds-C++=f", "--fields=+ne", "--output-format=json",
                          "-o", "-", *folders], capture_output=True, text=True, check=True).stdout
    long = []
    for line in out.splitlines():
        tag = json.loads(line)
        if tag.get("kind") != "function" or "end" not in tag or tag["name"].startswith("__anon"):
            continue
        if tag["path"].endswith("_test.cpp"):
            continue
        lines = tag["end"] - tag["line"] + 1
        if lines > limit:
            long.append((lines, f"{tag['path']}:{tag['line']}", tag.get("scope", "") + "::" + tag["name"]))
    for lines, where, name in sorted(long, reverse=True):
        print(f"{lines:5d} {where} {name.lstrip(':')}")
    return 1 if long else 0


if __name__ == "__main__":
    sys.exit(main())
