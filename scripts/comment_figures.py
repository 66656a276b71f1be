#!/usr/bin/env python3
"""comment_figures.py [ROOT]: code comments say what and why; measured figures live in bench/results and
docs/validation.md. Fails (exit 1, one "file:line: figure: comment" per offence) when a comment in the baker,
the runtime, the shaders or the scripts holds what reads as a measurement:
- a percentage that is not a stated rule (a tolerance, limit or target: "at most 5%", "within 2%", "≤ 3%");
- a duration (12 ms, 1.6 ms, 26 s, 3 minutes) or a speed-up (2× slower, 1.8x faster);
- a size in KB/MB/GB/MiB/GiB;
- a named test scene (Sponza, Sibenik, the helmet, the bunny, the Cornell box, Cycles) next to a number,
  as in "Sponza's court read 0.86".
ROOT: the repository (default: the folder above this script)."""
import pathlib
import re
import sys

SCANNED = ("baker", "runtime", "shaders", "scripts", "bench")
SKIPPED_PARTS = {"node_modules", "results", "build"}
C_LIKE = {".h", ".hpp", ".cpp", ".cc", ".inl", ".glsl", ".vert", ".frag", ".comp", ".geom", ".js", ".mjs"}
HASH_LIKE = {".py", ".sh", ".cmake", ".txt"}

# A percentage after one of these words is a rule (a tolerance, a pad, a limit), not a measurement.
RULE = re.compile(r"\b(?:at most|at least|within|by|plus|a|an|about|up to|under|over|limit|target|tolerance|"
                  r"allowance|cap)\s*$|[≤≥<>~]\s*$", re.I)
RULE_AFTER = re.compile(r"\s*(?:relative|of that|allowance)\b", re.I)
# A duration after one of these words is a setting (a period, a timeout), not a measurement.
SETTING = re.compile(r"\b(?:every|each|per|after|timeout|at most|within|up to|under)\s*$", re.I)
PERCENT = re.compile(r"\d+(?:\.\d+)?\s*%")
DURATION = re.compile(r"(?<![\w.])\d+(?:\.\d+)?(?:\s*(?:ms|µs|ns)|\s+(?:s|sec|seconds?|min|minutes?|hours?))\b")
SPEED = re.compile(r"\d+(?:\.\d+)?\s*[×x]\s*(?:slower|faster|quicker|the time|the memory)", re.I)
SIZE = re.compile(r"(\d+(?:\.\d+)?)\s*(?:KB|MB|GB|KiB|MiB|GiB)\b")
SCENE = re.compile(r"\b(?:Sponza|Sibenik|DamagedHelmet|helmet|bunny|Cornell|Cycles)\b[^.;]{0,60}?\d+\.\d+(?![-\w])|"
                   r"\d+\.\d+(?![-\w])[^.;]{0,40}?\b(?:Sponza|Sibenik|DamagedHelmet|bunny|Cycles)\b")


def comments(path):
    """(line number, comment text) for every comment line of a source file."""
    text = path.read_text(errors="replace").splitlines()
    out = []
    if path.suffix in HASH_LIKE:
        for n, line in enumerate(text, 1):
            m = re.search(r"(?:^|\s)#(?![!{(])(.*)$", line)
            if m and not re.match(r"\s*#\s*(include|define|if|endif|else|pragma)", line):
                out.append((n, m.group(1)))
        return out
    in_block = False
    for n, line in enumerate(text, 1):
        rest = line
        if in_block:
            end = rest.find("*/")
            out.append((n, rest if end < 0 else rest[:end]))
            if end < 0:
                continue
            in_block, rest = False, rest[end + 2:]
        code = re.sub(r'"(?:\\.|[^"\\])*"', '""', rest)  # string literals are not comments
        i, j = code.find("//"), code.find("/*")
        if i >= 0 and (j < 0 or i < j):
            out.append((n, code[i + 2:]))
        elif j >= 0:
            end = code.find("*/", j + 2)
            out.append((n, code[j + 2:] if end < 0 else code[j + 2:end]))
            in_block = end < 0
    return out


def power_of_two(text):
    return text.isdigit() and int(text) > 0 and int(text) & (int(text) - 1) == 0


def figures(comment):
    """The measured-looking figures of one comment line: percentages that are no rule and no closed form
    ("17% at ρ = 0.9"), durations that are no setting, speed-ups, sizes other than round powers of two (a
    budget), numbers beside a named scene."""
    found = []
    for m in PERCENT.finditer(comment):
        if not (RULE.search(comment[:m.start()]) or RULE_AFTER.match(comment, m.end()) or "=" in comment):
            found.append(m.group(0))
    found += [m.group(0) for m in DURATION.finditer(comment) if not SETTING.search(comment[:m.start()])]
    found += [m.group(0) for m in SIZE.finditer(comment) if not power_of_two(m.group(1))]
    for pattern in (SPEED, SCENE):
        found += [m.group(0) for m in pattern.finditer(comment)]
    return found


def offences(root):
    found = []
    for top in SCANNED:
        for path in sorted((root / top).rglob("*")):
            if (not path.is_file() or path.suffix not in C_LIKE | HASH_LIKE
                    or SKIPPED_PARTS & set(path.relative_to(root).parts) or path.name.endswith("_test.cpp")):
                continue
            for n, text in comments(path):
                for figure in figures(text):
                    found.append(f"{path.relative_to(root)}:{n}: {figure.strip()}: {text.strip()[:100]}")
    return found


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
    found = offences(root)
    for f in found:
        print(f)
    if found:
        print(f"comment_figures: {len(found)} measured figure(s) in code comments; put them in "
              "bench/results and docs/validation.md", file=sys.stderr)
        return 1
    print("comment_figures: no measured figures in code comments")
    return 0


if __name__ == "__main__":
    sys.exit(main())
