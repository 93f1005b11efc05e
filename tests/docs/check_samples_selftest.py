#!/usr/bin/env python3
"""Self-test of check_samples.py: a good tree passes; bad samples and bad links fail, each named
by file and line. Usage: check_samples_selftest.py"""
import pathlib
import subprocess
import sys
import tempfile

CHECKER = pathlib.Path(__file__).resolve().parent / "check_samples.py"

EXAMPLE = """// An example.
#include <cstdio>

int main() {
  std::printf("hello\\n");   
  return 0;
}
"""

GOOD_README = """# Title

## Quick start: the C++ sample

```cpp
int main() {
  std::printf("hello\\n");
  return 0;
```

```sh
anything goes in a shell block
```

See [the guide](docs/guide.md#a-heading-with-code-and-punctuation), [Quick start](#quick-start-the-c-sample),
[the second one](docs/guide.md#twice-1) and [a site](https://example.org/x.md#nothing).
"""

GOOD_GUIDE = """# Guide

## A heading with `code`, and punctuation!

## Twice

## Twice

Back to the [README](../README.md).
"""

BAD_GUIDE = GOOD_GUIDE + """
```python
print("not in any example")
```

```c++
int main() {
  return 0;
```

A [missing file](missing.md), a [missing heading](../README.md#no-such-heading) and
[another](#nope).
"""


def run(root):
    out = subprocess.run([sys.executable, CHECKER, root], capture_output=True, text=True)
    return out.returncode, out.stdout


def write_tree(root, guide):
    (root / "examples").mkdir()
    (root / "docs").mkdir()
    (root / "examples" / "hello.cpp").write_text(EXAMPLE)
    (root / "README.md").write_text(GOOD_README)
    (root / "docs" / "guide.md").write_text(guide)


def main():
    with tempfile.TemporaryDirectory() as tmp:
        good = pathlib.Path(tmp) / "good"
        good.mkdir()
        write_tree(good, GOOD_GUIDE)
        code, out = run(good)
        assert code == 0, f"a good tree failed:\n{out}"

        bad = pathlib.Path(tmp) / "bad"
        bad.mkdir()
        write_tree(bad, BAD_GUIDE)
        code, out = run(bad)
        assert code != 0, "a bad tree passed"
        lines = out.splitlines()
        expected = [
            "docs/guide.md:11: the python sample",
            "docs/guide.md:15: the c++ sample",
            "docs/guide.md:20: link to a missing file: missing.md",
            "docs/guide.md:20: link to a missing heading: ../README.md#no-such-heading",
            "docs/guide.md:21: link to a missing heading: #nope",
        ]
        for prefix in expected:
            assert any(line.startswith(prefix) for line in lines), f"missing '{prefix}' in:\n{out}"
        assert len(lines) == len(expected), f"unexpected problems:\n{out}"
    print("check_samples_selftest: passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
