#!/usr/bin/env python3
"""docs_check.py [ROOT]: the front page matches the tree and the validation document stays a manual.
Fails (exit 1, one "file: why" per offence) when
- a folder README.md's "## Layout" table names does not exist: the first column's folders (`runtime/`), a
  subfolder written as `name/` in a row's description (relative to that row's folder), and, in the `baker/`
  row, every module written in backticks (`scene`, `stages/{sky,gather}`), relative to baker/;
- a module folder (baker/X, and baker/stages/X, baker/evaluators/X) is missing from the `baker/` row;
- docs/validation.md is larger than MAX_VALIDATION_BYTES: its figures are generated tables and one short
  paragraph per section, and history is git's.
ROOT: the repository (default: the folder above this script)."""
import pathlib
import re
import sys

MAX_VALIDATION_BYTES = 40_000
GROUPS = ("stages", "evaluators")  # baker folders whose subfolders are modules of their own


def layout_rows(readme):
    """(folder, description) of every row of the table under README's "## Layout"."""
    section = re.search(r"^## Layout\n(.*?)(?=^## |\Z)", readme, re.S | re.M)
    if not section:
        return None
    rows = []
    for line in section.group(1).splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        m = re.fullmatch(r"`([^`]+)`", cells[0]) if len(cells) >= 2 else None
        if m:
            rows.append((m.group(1).rstrip("/"), "|".join(cells[1:])))
    return rows


def expand(token):
    """`a/{b,c}` -> [a, a/b, a/c]; `a` -> [a]."""
    m = re.fullmatch(r"([a-z_]+)/\{([a-z_,]+)\}", token)
    return [m.group(1)] + [f"{m.group(1)}/{x}" for x in m.group(2).split(",")] if m else [token]


def module_folders(baker):
    folders = []
    for d in sorted(p for p in baker.iterdir() if p.is_dir()):
        folders.append(d.name)
        if d.name in GROUPS:
            folders += [f"{d.name}/{s.name}" for s in sorted(p for p in d.iterdir() if p.is_dir())]
    return folders


def layout_offences(root):
    readme = (root / "README.md").read_text(encoding="utf-8")
    rows = layout_rows(readme)
    if not rows:
        return ["README.md: no \"## Layout\" table"]
    found = []
    named_modules = set()
    for folder, what in rows:
        if not (root / folder).is_dir():
            found.append(f"README.md: Layout names {folder}/, which does not exist")
            continue
        for sub in re.findall(r"`([a-z_]+)/`", what):
            if not (root / folder / sub).is_dir():
                found.append(f"README.md: Layout names {folder}/{sub}/, which does not exist")
        if folder == "baker":
            for token in re.findall(r"`([^`]+)`", what):
                if not re.fullmatch(r"[a-z_]+(/\{[a-z_,]+\})?", token):
                    continue
                for module in expand(token):
                    named_modules.add(module)
                    if not (root / "baker" / module).is_dir():
                        found.append(f"README.md: Layout names baker/{module}, which does not exist")
    if not any(folder == "baker" for folder, _ in rows):
        found.append("README.md: Layout has no `baker/` row")
    else:
        found += [f"README.md: Layout does not name the module folder baker/{m}"
                  for m in module_folders(root / "baker") if m not in named_modules]
    return found


def size_offences(root):
    doc = root / "docs" / "validation.md"
    size = doc.stat().st_size
    if size > MAX_VALIDATION_BYTES:
        return [f"docs/validation.md: {size} bytes, over {MAX_VALIDATION_BYTES}: keep the generated tables and one "
                "short paragraph per section; current figures only"]
    return []


def main():
    root = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent
    found = layout_offences(root) + size_offences(root)
    for line in found:
        print(line)
    if not found:
        print("README.md's Layout matches the folders; docs/validation.md is within "
              f"{MAX_VALIDATION_BYTES} bytes")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
