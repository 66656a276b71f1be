#!/usr/bin/env python3
"""layering.py [ROOT]: the evaluators are peers. Fails (exit 1, one "file:line: why" per offence) when a
file under baker/evaluators/X includes "evaluators/Y/..." for another evaluator Y, or a file under
baker/stages or baker/pipeline includes an evaluator implementation (evaluators/{gl,embree,reference}/...):
they may include only the interface (evaluators/evaluator.h, evaluators/bake_inputs.h). The one exception is
the evaluator factory (baker/pipeline/evaluator_factory.cpp), which makes the evaluators and wires them
together. Tests (*_test.cpp) may compare or combine evaluators and are left out;
their shared helpers live in baker/testing, outside both folders. Also fails when docs/architecture.md does not
name a module folder (baker/X, baker/stages/X, baker/evaluators/X, written out or as baker/evaluators/{a,b}) or
names one that is gone. ROOT: the repository (default: the folder above this script)."""
import os
import pathlib
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^">]+)[">]')
SOURCES = {".h", ".hpp", ".cpp", ".cc", ".inl"}


def is_test(path):
    return path.name.endswith("_test.cpp")


def evaluator_of(include, path, root, evaluators_dir):
    """The evaluator folder an include lands in (baker/ is the include root; "../x.h" is relative), or None."""
    base = root / "baker" if not include.startswith(".") else path.parent
    target = pathlib.Path(os.path.normpath(base / include))
    try:
        parts = target.relative_to(evaluators_dir).parts
    except ValueError:
        return None
    return parts[0] if len(parts) > 1 else None


# The one file outside baker/evaluators that may include the implementations: it makes them.
FACTORY = pathlib.Path("baker/pipeline/evaluator_factory.cpp")


def offences(root):
    evaluators_dir = root / "baker" / "evaluators"
    stages_dir = root / "baker" / "stages"
    pipeline_dir = root / "baker" / "pipeline"
    evaluators = sorted(p.name for p in evaluators_dir.iterdir() if p.is_dir())
    found = []
    for top, owner in [(evaluators_dir, "evaluator"), (stages_dir, "stage"), (pipeline_dir, "pipeline")]:
        for path in sorted(top.rglob("*")):
            if path.suffix not in SOURCES or not path.is_file() or is_test(path):
                continue
            if path.relative_to(root) == FACTORY:
                continue
            rel = path.relative_to(top)
            own = rel.parts[0] if owner == "evaluator" and len(rel.parts) > 1 else None
            for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
                m = INCLUDE.match(line)
                other = evaluator_of(m.group(1), path, root, evaluators_dir) if m else None
                if other not in evaluators or other == own:
                    continue
                why = (f"the {own} evaluator includes the {other} one" if own
                       else f"includes the {other} evaluator's implementation")
                fix = ("make it in pipeline/evaluator_factory.cpp" if owner == "pipeline"
                       else "be handed the evaluator")
                found.append(f"{path.relative_to(root)}:{number}: {why} ({line.strip()}); "
                             f"include evaluators/evaluator.h and {fix} instead")
    return found


def module_folders(root):
    """baker/X and, for the areas that group modules, baker/stages/X and baker/evaluators/X."""
    baker = root / "baker"
    folders = []
    for d in sorted(p for p in baker.iterdir() if p.is_dir()):
        folders.append(f"baker/{d.name}")
        if d.name in ("stages", "evaluators"):
            folders += [f"baker/{d.name}/{s.name}" for s in sorted(p for p in d.iterdir() if p.is_dir())]
    return folders


def architecture_offences(root):
    doc = root / "docs" / "architecture.md"
    text = doc.read_text(errors="replace")
    named = set(re.findall(r"baker/[a-z_]+(?:/[a-z_]+)?", text))
    for group, members in re.findall(r"(baker/[a-z_]+)/\{([a-z_,]+)\}", text):
        named |= {group} | {f"{group}/{m}" for m in members.split(",")}
    folders = module_folders(root)
    found = [f"docs/architecture.md: does not name the module folder {f}" for f in folders if f not in named]
    for f in sorted(named):
        top = "/".join(f.split("/")[:2])
        if not (root / f).exists() and (f.count("/") == 1 or top in ("baker/stages", "baker/evaluators")):
            found.append(f"docs/architecture.md: names {f}, which does not exist")
    return found


def main():
    root = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent
    found = offences(root)
    layout = architecture_offences(root)
    for line in found + layout:
        print(line)
    if not found:
        print("evaluators are peers: no evaluator includes another, no stage includes one, and in the pipeline "
              "only the evaluator factory does")
    if not layout:
        print("docs/architecture.md names every module folder and none that is gone")
    found += layout
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
