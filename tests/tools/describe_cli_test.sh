#!/usr/bin/env bash
# robotalk-describe from the outside: tables, JSON, and one clear error line
# with a non-zero exit for each kind of bad file.
#   describe_cli_test.sh PATH/TO/robotalk-describe MODELS_DIR
set -u
describe=$1
models=$2
. "$(dirname "$0")/../lib.sh"  # $tmp, check

# A good file: a table naming the robot, its head joint and its total mass.
"$describe" "$models/pioneer2dx_pantilt.urdf" >"$tmp/out" 2>"$tmp/err"
check "good file exits 0" test $? -eq 0
check "table names the robot" grep -q "^Robot '" "$tmp/out"
check "table lists links and joints" grep -q "^Links" "$tmp/out"
check "table shows total mass" grep -q "total mass" "$tmp/out"
check "shipped model has no warnings" test ! -s "$tmp/err"

# JSON parses and carries the same robot.
"$describe" --json "$models/pioneer2dx_pantilt.urdf" >"$tmp/json"
check "json exits 0" test $? -eq 0
check "json is valid" python3 -c "import json,sys; d=json.load(open('$tmp/json')); sys.exit(0 if d['links'] and d['num_dofs']>0 else 1)"

# --merge-chains makes the pan-tilt head one 2-dof joint.
"$describe" --json --merge-chains "$models/pioneer2dx_pantilt.urdf" >"$tmp/merged"
check "merged head has a 2-dof joint" python3 -c "import json,sys; d=json.load(open('$tmp/merged')); sys.exit(0 if any(len(j['dofs'])==2 for j in d['joints']) else 1)"

bad() {  # bad NAME EXPECTED-FRAGMENT FILE
  local name=$1 fragment=$2 file=$3
  "$describe" "$file" >"$tmp/out" 2>"$tmp/err"
  local rc=$?
  check "$name: non-zero exit" test $rc -eq 1
  check "$name: exactly one line" test "$(wc -l <"$tmp/err")" -eq 1
  check "$name: message names '$fragment'" grep -qi -- "$fragment" "$tmp/err"
}

bad "missing file" "no_such_file.urdf" "$tmp/no_such_file.urdf"
printf '<robot name="x"><link name="a">' >"$tmp/malformed.urdf"
bad "malformed XML" "malformed.urdf" "$tmp/malformed.urdf"
cat >"$tmp/unknown_link.urdf" <<'XML'
<robot name="x"><link name="a"/><link name="b"/>
<joint name="j" type="fixed"><parent link="a"/><child link="ghost"/></joint></robot>
XML
bad "unknown link" "ghost" "$tmp/unknown_link.urdf"
cat >"$tmp/negative_mass.urdf" <<'XML'
<robot name="x"><link name="heavy"><inertial><mass value="-2"/>
<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>
XML
bad "negative mass" "heavy" "$tmp/negative_mass.urdf"

# Review 13: a name with a control character (an XML character reference) in
# an error the importer writes before the model is built (an unknown child
# link): the line named it raw, its terminal escape reaching the terminal.
cat >"$tmp/escape.urdf" <<'XML'
<robot name="x"><link name="a"/><link name="b"/>
<joint name="j" type="fixed"><parent link="a"/><child link="gh&#x1b;]0;owned&#x7;ost"/></joint></robot>
XML
bad "a name with a terminal escape" 'gh\\x1b]0;owned\\x07ost' "$tmp/escape.urdf"
check "a name with a terminal escape: no ESC or BEL reaches the terminal: $(cat -v "$tmp/err")" \
  bash -c "! LC_ALL=C grep -q \$'\x1b\\|\x07' '$tmp/err'"

# Limits (issue 9): a 100,000-deep file used to crash with SIGSEGV (rc 139).
python3 -c "import sys; sys.stdout.write('<robot name=\"x\"><link name=\"a\"/>' + '<x>'*100000 + '</x>'*100000 + '</robot>')" >"$tmp/nested.urdf"
bad "100,000-deep XML" "nested 100001 deep.*max_xml_depth" "$tmp/nested.urdf"
"$describe" --max-bytes 1000 "$models/pioneer2dx_pantilt.urdf" >/dev/null 2>"$tmp/err"
check "--max-bytes refuses a bigger file" test $? -eq 1
check "--max-bytes names the limit" grep -q "limit of 1000 bytes (UrdfImportOptions::max_file_bytes)" "$tmp/err"
"$describe" --max-depth 2 "$models/pioneer2dx_pantilt.urdf" >/dev/null 2>"$tmp/err"
check "--max-depth 2 refuses the shipped model" grep -q "the limit is 2 (UrdfImportOptions::max_xml_depth)" "$tmp/err"
"$describe" --max-depth 0 "$models/pioneer2dx_pantilt.urdf" >/dev/null 2>&1
check "--max-depth 0 is a usage error" test $? -eq 2

"$describe" >/dev/null 2>&1
check "no argument is a usage error" test $? -eq 2
"$describe" --bogus x.urdf >/dev/null 2>&1
check "unknown option is a usage error" test $? -eq 2
# A known option without its value is named so (before: "unknown option '--name'").
"$describe" "$models/pioneer2dx_pantilt.urdf" --name >/dev/null 2>"$tmp/err"
check "a trailing --name is a usage error" test $? -eq 2
check "a trailing --name needs a value: $(head -1 "$tmp/err")" grep -q -- "^robotalk-describe: --name needs a value" "$tmp/err"

echo "$pass passed, $failures failed"
[ "$failures" -eq 0 ]
