#!/usr/bin/python3
"""docs/safety.md names a test for every safety promise: each name must be a
test of this suite, or the promise is proven by nothing (a renamed or deleted
test leaves the table lying). Checks every `Suite.Name` (GoogleTest, `*`
allowed) and every ctest name (`snake_case`, `*` allowed) in the tables'
test column against `ctest -N` of this build.

usage: safety_names_test.py SOURCE_DIR BUILD_DIR
"""
import re
import subprocess
import sys

source, build = sys.argv[1], sys.argv[2]
listing = subprocess.run(["ctest", "--test-dir", build, "-N"], capture_output=True, text=True, check=True).stdout
tests = set(re.findall(r"Test +#\d+: (\S+)", listing))
if len(tests) < 100:
    sys.exit(f"FAIL: ctest -N in {build} lists {len(tests)} tests; the build is not configured")

gtest = re.compile(r"^[A-Za-z0-9_*]+(/[A-Za-z0-9_*]+)?\.[A-Za-z0-9_*/]+$")
ctest_name = re.compile(r"^[a-z0-9_*]+$")
checked, missing = 0, []
for number, line in enumerate(open(f"{source}/docs/safety.md", encoding="utf-8"), 1):
    cells = [c.strip() for c in line.split("|")]
    if len(cells) < 5 or cells[1] in ("promise", "---"):
        continue
    for name in re.findall(r"`([^`]+)`", cells[2]):
        if not (gtest.match(name) or ctest_name.match(name)) or "." not in name and "_" not in name:
            continue  # a command line, a file or an option, not a test name
        pattern = re.compile("^" + re.escape(name).replace(r"\*", ".*") + "$")
        checked += 1
        if not any(pattern.match(t) for t in tests):
            missing.append(f"docs/safety.md:{number}: `{name}` is no test of this suite")

for m in missing:
    print("FAIL:", m)
print(f"{checked - len(missing)} of {checked} test names in docs/safety.md found in ctest -N")
sys.exit(1 if missing or checked < 50 else 0)
