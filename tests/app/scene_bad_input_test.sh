#!/usr/bin/env bash
# Bad scene files through the real process (SCENE.md, Principles): every
# case through `sylva check` and `sylva render -o out.png` is exit 2 with
# the error at its file:line:col on stderr, and nothing is written to the
# output path (an existing file keeps its bytes, a missing one is not
# created). Hostile files (a FIFO, /dev/zero behind a symbolic link, 100 MB,
# a directory, an include of /dev/urandom, a billion-laughs DOCTYPE, deep
# nesting) end in seconds, under a memory limit, without a crash.
# Usage: scene_bad_input_test.sh SYLVA_BINARY WORK_DIR [graphics|nographics]
set -euo pipefail
sylva="$1"; work="$2"; graphics="${3:-graphics}"
rm -rf "$work"; mkdir -p "$work"; cd "$work"
fail() { echo "FAIL: $*"; exit 1; }
w() { printf '%s' "$2" > "$1"; }

# Runs "$@" with a 20 s limit and at most 2 GiB of address space for check
# (render maps the GL driver, so its peak resident size is checked instead:
# at most 300 MB). Sets code, err (stderr) and kb (peak resident KiB).
# Under AddressSanitizer (scripts/sanitize.sh sets ASAN_OPTIONS) the
# address-space limit would stop the sanitizer's shadow memory from being
# mapped, and its allocator inflates the resident size: neither bound is
# applied there (the plain build checks them).
sanitized=""
[[ -n "${ASAN_OPTIONS:-}" ]] && sanitized=1
run() {
  local limit=""
  [[ $1 == check && -z "$sanitized" ]] && limit="ulimit -v 2097152;"
  local timer=""  # GNU time for the peak resident size, where installed
  [[ -x /usr/bin/time ]] && timer="/usr/bin/time -f 'maxrss %M' -o time.txt"
  echo "maxrss 0" > time.txt
  set +e
  bash -c "$limit exec $timer timeout 20 \"\$@\"" _ "$sylva" "$@" > /dev/null 2> err.txt
  code=$?
  set -e
  err=$(cat err.txt)
  kb=$(sed -n 's/^maxrss //p' time.txt)
  [[ $code != 124 ]] || fail "$* hung (killed after 20 s)"
  (( code < 128 )) || fail "$* crashed (exit $code): $err"
  [[ -n "$sanitized" ]] || (( ${kb:-0} < 307200 )) || fail "$* used $kb KiB"
}

# expect NAME FILE WHERE MESSAGE [-D ...]: check and render both exit 2 with
# "WHERE: error: ...MESSAGE" on stderr (WHERE may be "file:line:col" or
# "file:"), the existing output untouched and a new one not created.
expect() {
  local name="$1" file="$2" where="$3" message="$4"; shift 4
  run check "$file" "$@"
  [[ $code == 2 ]] || fail "$name: check exited $code: $err"
  grep -qF -- "$where" err.txt || fail "$name: check: expected at '$where': $err"
  grep -qF -- "$message" err.txt || fail "$name: check: expected '$message': $err"
  if [[ $graphics == graphics ]]; then
    echo "keep me" > kept.png
    run render "$file" -o kept.png --size 64x48 "$@"
    [[ $code == 2 ]] || fail "$name: render exited $code: $err"
    grep -qF -- "$where" err.txt || fail "$name: render: expected at '$where': $err"
    grep -qF -- "$message" err.txt || fail "$name: render: expected '$message': $err"
    [[ $(cat kept.png) == "keep me" ]] || fail "$name: render changed the existing output"
    rm -f new.png
    run render "$file" -o new.png --size 64x48 "$@"
    [[ $code == 2 ]] || fail "$name: render to a new path exited $code"
    [[ ! -e new.png ]] || fail "$name: render wrote new.png"
    [[ -z $(compgen -G "*.tmp-*") ]] || fail "$name: render left a temporary file: $(ls)"
  fi
  echo "ok: $name: $(head -1 err.txt | cut -c1-160)"
}

w ok.lsys $'axiom: F\nF --> F[+F]F\n'
w bad.lsys $'// a grammar with an error on line 3\naxiom: F\nF --> F[+F\n'

# SCENE.md's Principles, one by one.
w unknown_element.xml $'<scene version="1">\n  <terain/>\n</scene>\n'
expect unknown_element unknown_element.xml "unknown_element.xml:2:3: error:" "unknown element <terain> (did you mean 'terrain'?)"
w unknown_attribute.xml $'<scene version="1">\n  <terrain id="hill" resolutoin="33"/>\n</scene>\n'
expect unknown_attribute unknown_attribute.xml "unknown_attribute.xml:2:22: error:" "unknown attribute 'resolutoin' on <terrain> (did you mean 'resolution'?)"
w missing.xml $'<scene version="1">\n  <plant position="0 0 0"/>\n</scene>\n'
expect missing_required missing.xml "missing.xml:2:3: error:" "<plant> needs a 'grammar'"
w wrong_type.xml $'<scene version="1">\n  <terrain height="tall"/>\n</scene>\n'
expect wrong_type wrong_type.xml "wrong_type.xml:2:20: error:" "expected a decimal number, found 'tall'"
w nan_z.xml $'<scene version="1">\n  <wind velocity="1 2 nan"/>\n</scene>\n'
expect nan_in_z nan_z.xml "nan_z.xml:2:23: error:" "found 'nan'"
w range.xml $'<scene version="1">\n  <terrain gain="1.5"/>\n</scene>\n'
expect out_of_range range.xml "range.xml:2:18: error:" "'gain': must be between 0 and 1"
w dup.xml $'<scene version="1">\n  <terrain id="a"/>\n  <cloth id="a"/>\n</scene>\n'
expect duplicate_id dup.xml "dup.xml:3:14: error:" "duplicate id 'a' (first on <terrain> at dup.xml:2:3)"
w dangling.xml $'<scene version="1">\n  <terrain id="hill"/>\n  <forest grammar="ok.lsys" count="1" on="hil"/>\n</scene>\n'
expect dangling_id dangling.xml "dangling.xml:3:43: error:" "no element has the id 'hil' (did you mean 'hill'?)"
w defs.xml $'<scene version="1">\n  <default name="n" value="2"/>\n  <plant grammar="ok.lsys" steps="$n"/>\n</scene>\n'
expect unknown_define defs.xml "sylva: error: -D m:" "declares no parameter 'm'" -D m=4
w undeclared.xml $'<scene version="1">\n  <plant grammar="ok.lsys" steps="$m"/>\n</scene>\n'
expect unknown_parameter undeclared.xml "undeclared.xml:2:35: error:" "unknown parameter '\$m'"
expect define_bad_value defs.xml "defs.xml:3:35: error:" "after parameter substitution" -D n=x
w cycle_a.xml $'<scene version="1">\n  <include file="cycle_b.xml"/>\n</scene>\n'
w cycle_b.xml $'<scene version="1">\n  <include file="cycle_a.xml"/>\n</scene>\n'
expect include_cycle cycle_a.xml "cycle_b.xml:2:12: error:" "include cycle: $work/cycle_a.xml -> $work/cycle_b.xml -> $work/cycle_a.xml"
for i in $(seq 0 16); do
  w "inc$i.xml" "<scene version=\"1\">
  <include file=\"inc$((i + 1)).xml\"/>
</scene>
"
done
w inc17.xml $'<scene version="1">\n  <sky/>\n</scene>\n'
expect include_16th inc0.xml "inc15.xml:2:12: error:" "includes nest deeper than 15 levels"
# ... and 15 nested includes load (inc2 -> ... -> inc17 is the root and 15).
run check inc2.xml
[[ $code == 0 ]] || fail "15 nested includes: exit $code: $err"
echo "ok: 15 nested includes load"
w memory.xml $'<scene version="1">\n  <particles max="1e11"><emitter/></particles>\n</scene>\n'
expect beyond_memory memory.xml "memory.xml:2:19: error:" "memory"
w terrain_memory.xml $'<scene version="1">\n  <terrain resolution="1000000"/>\n</scene>\n'
expect terrain_over_limit terrain_memory.xml "terrain_memory.xml:2:24: error:" "above the limit of 8193"
w count.xml $'<scene version="1">\n  <forest grammar="ok.lsys" count="1.5"/>\n</scene>\n'
expect count_not_whole count.xml "count.xml:2:36: error:" "expected a whole number"
w count_e.xml $'<scene version="1">\n  <particles max="1e6"><emitter burst="2.5e0"/></particles>\n</scene>\n'
expect burst_not_whole count_e.xml "count_e.xml:2:40: error:" "expected a whole number"
w grammar.xml $'<scene version="1">\n\n  <plant grammar="bad.lsys" steps="2"/>\n</scene>\n'
expect grammar_error grammar.xml "bad.lsys:3:8: error:" "grammar.xml:3:19: note: in the grammar of this <plant>"
w no_grammar.xml $'<scene version="1">\n  <forest grammar="none.lsys" count="3"/>\n</scene>\n'
expect missing_grammar no_grammar.xml "no_grammar.xml:2:20: error:" "grammar 'none.lsys': cannot read file"
w malformed.xml $'<scene version="1">\n  <wind gust="1">\n</scene>\n'
expect malformed_xml malformed.xml "malformed.xml:3:" "malformed XML"

# Hostile files.
mkfifo fifo.xml
expect fifo fifo.xml "fifo.xml: error:" "not a regular file"
ln -s /dev/zero zero.xml
expect dev_zero_link zero.xml "zero.xml: error:" "not a regular file"
mkdir dir.xml
expect directory dir.xml "dir.xml: error:" "directory"
head -c 100000000 /dev/zero | tr '\0' ' ' > big.xml
expect hundred_mb big.xml "big.xml: error:" "larger than the limit"
w urandom.xml $'<scene version="1">\n  <include file="/dev/urandom"/>\n</scene>\n'
expect include_urandom urandom.xml "urandom.xml:2:12: error:" "cannot include '/dev/urandom': is not a regular file"
ln -s /dev/urandom random.xml
w urandom_link.xml $'<scene version="1">\n  <include file="random.xml"/>\n</scene>\n'
expect include_urandom_link urandom_link.xml "urandom_link.xml:2:12: error:" "cannot include 'random.xml': is not a regular file"
w missing_include.xml $'<scene version="1">\n  <include file="nowhere.xml"/>\n</scene>\n'
expect include_missing missing_include.xml "missing_include.xml:2:12: error:" "cannot include 'nowhere.xml': cannot read file"
# Billion laughs: pugixml does not expand entities declared in a DOCTYPE,
# so the value stays '&lol9;' (an error where a colour is expected).
cat > laughs.xml <<'EOF'
<?xml version="1.0"?>
<!DOCTYPE lolz [
 <!ENTITY lol "lol">
 <!ENTITY lol1 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">
 <!ENTITY lol2 "&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;">
 <!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">
 <!ENTITY lol4 "&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;">
 <!ENTITY lol5 "&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;">
 <!ENTITY lol6 "&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;">
 <!ENTITY lol7 "&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;">
 <!ENTITY lol8 "&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;">
 <!ENTITY lol9 "&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;">
]>
<scene version="1">
  <sky top="&lol9;"/>
</scene>
EOF
expect billion_laughs laughs.xml "laughs.xml:15:13: error:" "expected a colour"
# 100,000 nested elements (pugixml parses without recursion; the reader
# refuses them at the first level no scene element has).
python3 -c "
print('<scene version=\"1\">')
print('<particles>' * 100000 + '</particles>' * 100000)
print('</scene>')" > deep.xml
expect deep_nesting deep.xml "deep.xml:2:34: error:" "elements nest deeper than any scene element can"
# 60 MB (under the 64 MiB limit): a comment of spaces loads in bounded
# memory (run() fails above 300 MB resident).
python3 -c "
import sys
sys.stdout.write('<scene version=\"1\">\n<!--' + ' ' * 60000000 + '-->\n<sky/>\n</scene>\n')" > sixty.xml
run check sixty.xml
[[ $code == 0 ]] || fail "a 60 MB scene: exit $code: $err"
echo "ok: a 60 MB scene loads with $kb KiB resident"
# --strict: a warning of the simulation (here a wind that cannot act on
# particles without <drag>) fails render, mesh and simulate alike, at its
# line, before anything is written; without --strict it is a warning and
# exit 0.
cat > warned.xml <<'EOF'
<scene version="1">
  <wind velocity="2 0 0"/>
  <particles id="rain" max="10">
    <emitter shape="point" at="0 1 0" rate="10"/>
  </particles>
</scene>
EOF
for cmd in "simulate --duration 0.1" "mesh -o strict.glb"; do
  run $cmd warned.xml --strict
  [[ $code == 2 ]] || fail "$cmd --strict with a warning exited $code: $err"
  grep -qF "warned.xml:3:" err.txt || fail "$cmd --strict: expected the warning's line: $err"
  [[ ! -e strict.glb ]] || fail "$cmd --strict wrote its output"
  run $cmd warned.xml
  [[ $code == 0 ]] || fail "$cmd without --strict exited $code: $err"
  rm -f strict.glb
done
if [[ $graphics == graphics ]]; then
  run render warned.xml -o strict.png --size 64x48 --strict
  [[ $code == 2 ]] || fail "render --strict with a warning exited $code: $err"
  grep -qF "warned.xml:3:" err.txt || fail "render --strict: expected the warning's line: $err"
  [[ ! -e strict.png ]] || fail "render --strict wrote its output"
fi
echo "ok: --strict turns a simulation warning into exit 2 for simulate, mesh and render"
echo "ok: all bad scenes are exit 2 at their line and column"
