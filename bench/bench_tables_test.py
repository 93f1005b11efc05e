"""scripts/bench-tables --check on a scratch copy of the docs: passes on the generated tables
(the README's headline block included), and fails, naming the file and the block, after a
number in a table is edited by hand, on an unknown table, on a missing JSON file and on the JSON
of a --quick run.

    python3 bench/bench_tables_test.py SOURCE_DIR SCRATCH_DIR
"""
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

source, scratch = Path(sys.argv[1]), Path(sys.argv[2])
script = source / "scripts" / "bench-tables"
failures = []


def run(*args):
    proc = subprocess.run([sys.executable, str(script), "--root", str(scratch), *args], capture_output=True,
                          text=True)
    return proc.returncode, proc.stdout + proc.stderr


def expect(what, code, output, want_code, want_text=None):
    if code != want_code or (want_text and want_text not in output):
        failures.append(f"{what}: exit code {code} (wanted {want_code}), output:\n{output}")


shutil.rmtree(scratch, ignore_errors=True)
(scratch / "docs" / "bench").mkdir(parents=True)
for page in (source / "docs").glob("*.md"):
    shutil.copy(page, scratch / "docs" / page.name)
for data in (source / "docs" / "bench").glob("*.json"):
    shutil.copy(data, scratch / "docs" / "bench" / data.name)
readme = scratch / "README.md"
readme.write_text("# tightbvh\n\n<!-- bench-table headline -->\n<!-- /bench-table -->\n\nText after.\n")

expect("rewrite", *run(), 0)
generated = readme.read_text()
expect("check after rewrite", *run("--check"), 0)
if "docs/benchmarks.md#" not in generated or generated.count("\n| ") < 3:
    failures.append(f"the headline block was not generated:\n{generated}")

# A number in a table edited by hand: the first ratio of the headline's table.
edited = re.sub(r"(\| )(\d+)\.(\d+)x", lambda m: f"{m.group(1)}{int(m.group(2)) + 1}.{m.group(3)}x", generated,
                count=1)
if edited == generated:
    failures.append("found no ratio to edit in the headline block")
readme.write_text(edited)
expect("check after a hand edit", *run("--check"), 1, "README.md: block 'headline' differs")
readme.write_text(generated)
expect("check after restoring", *run("--check"), 0)

readme.write_text(generated + "\n<!-- bench-table no-such-table -->\n<!-- /bench-table -->\n")
expect("unknown table", *run("--check"), 1, "README.md: block 'no-such-table': unknown table")
readme.write_text(generated)

refit = scratch / "docs" / "bench" / "refit.json"
kept = refit.read_text()
refit.unlink()
expect("missing JSON", *run("--check"), 1, "docs/benchmarks.md: block 'refit': missing docs/bench/refit.json")
doc = json.loads(kept)
doc["run"]["quick"] = True
refit.write_text(json.dumps(doc))
expect("JSON of a --quick run", *run("--check"), 1, "from a --quick run")
refit.write_text(kept)
expect("check after restoring the JSON", *run("--check"), 0)

for f in failures:
    print(f"FAIL {f}")
sys.exit(1 if failures else 0)
