#!/usr/bin/env python3
"""Checks the documentation's code samples and links.

Scans README.md and docs/**/*.md (CHANGELOG.md is history and is not scanned) and fails, listing
file:line, when
  (a) a fenced code block whose info string is cpp, c++, python, py or cmake is not a verbatim,
      contiguous run of whole lines (trailing whitespace ignored) of some file under examples/
      that git tracks (the examples are built and run by the tests, so the samples cannot rot);
  (b) a relative Markdown link points to a missing file, or to a heading anchor that the target
      Markdown file does not have (GitHub's anchor rules).

Usage: check_samples.py [ROOT]   (ROOT: the repository, default: two folders above this script)
"""
import os
import pathlib
import re
import subprocess
import sys
import unicodedata

CHECKED_LANGUAGES = {"cpp", "c++", "python", "py", "cmake"}
FENCE = re.compile(r"^(?P<indent> {0,3}|\s*)(?P<fence>`{3,}|~{3,})\s*(?P<info>[^`\s]*)")
INLINE_LINK = re.compile(r"!?\[(?P<text>(?:[^\[\]]|\[[^\]]*\])*)\]\((?P<target><[^>]*>|[^()\s]+)(?:\s+\"[^\"]*\")?\)")
REFERENCE_DEFINITION = re.compile(r"^ {0,3}\[[^\]]+\]:\s+(?P<target>\S+)")
HTML_ANCHOR = re.compile(r"<a\s+(?:name|id)=\"([^\"]+)\"", re.IGNORECASE)
CODE_SPAN = re.compile(r"(`+)(?:.+?)\1")
SCHEME = re.compile(r"^[a-zA-Z][a-zA-Z0-9+.-]*:")


def documentation_files(root):
    files = []
    readme = root / "README.md"
    if readme.is_file():
        files.append(readme)
    docs = root / "docs"
    if docs.is_dir():
        files.extend(sorted(p for p in docs.rglob("*.md") if p.is_file()))
    return files


def example_files(root):
    """The files under examples/ that git tracks (every file there when ROOT is not a git work tree)."""
    try:
        out = subprocess.run(["git", "-C", str(root), "ls-files", "-z", "--", "examples"],
                             check=True, capture_output=True, text=True)
        names = [n for n in out.stdout.split("\0") if n]
        if names or (root / ".git").exists():
            return [root / n for n in names]
    except (OSError, subprocess.CalledProcessError):
        pass
    examples = root / "examples"
    return sorted(p for p in examples.rglob("*") if p.is_file()) if examples.is_dir() else []


def read_lines(path):
    try:
        return path.read_text(encoding="utf-8").splitlines()
    except (UnicodeDecodeError, OSError):
        return None


def fenced_blocks(lines):
    """Yields (first line number of the fence, info string, content lines) of every fenced block,
    and marks each line as inside code or not (for the link scan)."""
    in_code = [False] * len(lines)
    blocks = []
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        indent, fence, info = len(m.group("indent")), m.group("fence"), m.group("info").lower()
        start = i
        body = []
        i += 1
        while i < len(lines):
            stripped = lines[i].strip()
            if stripped.startswith(fence[0] * len(fence)) and stripped.strip(fence[0]) == "":
                break
            line = lines[i]
            body.append(line[min(indent, len(line) - len(line.lstrip(" "))):])
            i += 1
        for k in range(start, min(i + 1, len(lines))):
            in_code[k] = True
        blocks.append((start + 1, info, body))
        i += 1
    return blocks, in_code


def contains_run(haystack, needle):
    if not needle or len(needle) > len(haystack):
        return False
    first = needle[0]
    for start, line in enumerate(haystack[: len(haystack) - len(needle) + 1]):
        if line == first and haystack[start:start + len(needle)] == needle:
            return True
    return False


def github_anchor(heading):
    """GitHub's anchor of a heading: links and markup reduced to their text, lower case,
    punctuation dropped (letters, digits, spaces, '-' and '_' kept), spaces to hyphens."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)
    text = re.sub(r"<[^>]+>", "", text)
    text = text.strip().lower()
    kept = []
    for ch in text:
        category = unicodedata.category(ch)
        if ch in "-_ " or category[0] in "LN" or category == "Mn":
            kept.append(ch)
    return "".join(kept).replace(" ", "-")


def anchors_of(lines):
    _, in_code = fenced_blocks(lines)
    anchors = set()
    seen = {}
    for number, line in enumerate(lines):
        if in_code[number]:
            continue
        anchors.update(HTML_ANCHOR.findall(line))
        m = re.match(r"^ {0,3}(#{1,6})\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        base = github_anchor(m.group(2))
        count = seen.get(base, 0)
        seen[base] = count + 1
        anchors.add(base if count == 0 else f"{base}-{count}")
    return anchors


def check_links(path, lines, in_code, anchor_cache):
    problems = []
    for number, line in enumerate(lines, start=1):
        if in_code[number - 1]:
            continue
        text = CODE_SPAN.sub(lambda m: " " * len(m.group(0)), line)
        targets = [m.group("target") for m in INLINE_LINK.finditer(text)]
        ref = REFERENCE_DEFINITION.match(text)
        if ref:
            targets.append(ref.group("target"))
        for target in targets:
            target = target.strip("<>")
            if SCHEME.match(target) or target.startswith("//"):
                continue
            file_part, _, anchor = target.partition("#")
            resolved = path if not file_part else (path.parent / file_part)
            if not resolved.exists():
                problems.append(f"{number}: link to a missing file: {target}")
                continue
            if anchor and resolved.is_file() and resolved.suffix.lower() == ".md":
                key = resolved.resolve()
                if key not in anchor_cache:
                    anchor_cache[key] = anchors_of(read_lines(resolved) or [])
                if anchor.lower() not in anchor_cache[key]:
                    problems.append(f"{number}: link to a missing heading: {target}")
    return problems


def check(root):
    root = pathlib.Path(root).resolve()
    examples = {}
    for example in example_files(root):
        lines = read_lines(example)
        if lines is not None:
            examples[example] = [line.rstrip() for line in lines]
    problems = []
    anchor_cache = {}
    for doc in documentation_files(root):
        lines = read_lines(doc) or []
        name = os.path.relpath(doc, root)
        blocks, in_code = fenced_blocks(lines)
        for number, info, body in blocks:
            if info not in CHECKED_LANGUAGES:
                continue
            sample = [line.rstrip() for line in body]
            if not any(contains_run(example, sample) for example in examples.values()):
                problems.append(f"{name}:{number}: the {info} sample is not a verbatim excerpt of a file under examples/")
        problems.extend(f"{name}:{p}" for p in check_links(doc, lines, in_code, anchor_cache))
    return problems


def main(argv):
    root = argv[1] if len(argv) > 1 else pathlib.Path(__file__).resolve().parents[2]
    problems = check(root)
    for p in problems:
        print(p)
    if problems:
        print(f"check_samples: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    print("check_samples: every sample is an excerpt of examples/ and every relative link resolves")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
