#!/usr/bin/env bash
# The viewer playing a scene, in a real window under Xvfb:
#  1. `sylva view fireworks.xml --time 3 --screenshot` shows the fireworks
#     (bright pixels away from the panel that differ from the sky), and the
#     picture at --time 0 has none: --time is honoured;
#  2. a scene with an error exits 2 in screenshot mode, naming file:line:col,
#     and writes no picture; --time on a grammar is an error;
#  3. a running viewer reloads when the scene or a grammar it names changes:
#     an error is reported (and the viewer keeps running), a fix loads again.
# Usage: viewer_scene_test.sh SYLVA_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
sylva="$1"; src="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
display=":$((200 + ($$ + 250) % 500))"
Xvfb "$display" -screen 0 1280x800x24 -nolisten tcp >"$work/xvfb.log" 2>&1 &
xvfb=$!
viewer=""
cleanup() { [[ -n "$viewer" ]] && kill "$viewer" 2>/dev/null; kill "$xvfb" 2>/dev/null; true; }
trap cleanup EXIT
export DISPLAY="$display"
for _ in $(seq 50); do [[ -e "/tmp/.X11-unix/X${display#:}" ]] && break; sleep 0.1; done

# Bright pixels outside the panel (top left, 380x260) that differ from the
# sky of their row (the rightmost pixel) by more than 60 in some channel.
bright() {
  python3 - "$1" "$src/tests/app" <<'PY'
import sys
sys.dont_write_bytecode = True  # nothing written into the source tree
sys.path.insert(0, sys.argv[2])
import png_rows
w, h, rows = png_rows.read(sys.argv[1])
assert w == 960 and h == 540, (w, h)
count = 0
for y, row in enumerate(rows):
    sky = row[4 * (w - 1):4 * (w - 1) + 3]
    for x in range(w):
        if x < 380 and y < 260: continue
        if max(abs(row[4 * x + k] - sky[k]) for k in range(3)) > 60: count += 1
print(count)
PY
}

"$sylva" view "$src/examples/scenes/fireworks.xml" --time 3 --screenshot "$work/t3.png" \
  --frames 3 --size 960x540 | tee "$work/t3.out"
grep -q "at t = 3 s" "$work/t3.out"
"$sylva" view "$src/examples/scenes/fireworks.xml" --screenshot "$work/t0.png" --frames 3 \
  --size 960x540
n3=$(bright "$work/t3.png"); n0=$(bright "$work/t0.png")
echo "pixels off the sky: $n3 at t = 3 s, $n0 at t = 0"
[[ "$n3" -gt 150 ]] || { echo "the fireworks are not in the picture at t = 3"; exit 1; }
[[ "$n3" -gt $((n0 + 150)) ]] || { echo "--time 3 shows no more than t = 0"; exit 1; }

# Errors: a bad scene exits 2 with its location and writes nothing.
printf '<scene version="1">\n  <sky topp="#000000"/>\n</scene>\n' > "$work/bad.xml"
set +e
"$sylva" view "$work/bad.xml" --screenshot "$work/bad.png" --frames 3 --size 640x360 \
  2>"$work/bad.err"
code=$?
set -e
cat "$work/bad.err"
[[ $code -eq 2 ]] || { echo "a bad scene exited $code, not 2"; exit 1; }
grep -q "bad.xml:2:8: error: unknown attribute 'topp'" "$work/bad.err"
[[ ! -e "$work/bad.png" ]]
set +e
"$sylva" view "$src/grammars/abop/fig2_06a_monopodial.lsys" --time 2 2>"$work/grammar.err"
code=$?
set -e
[[ $code -eq 2 ]] && grep -q "is for scenes" "$work/grammar.err"

# Live reload of the scene and of a grammar it names.
cp "$src/grammars/abop/fig2_07a_sympodial.lsys" "$work/tree.lsys"
# A min-distance too large for the row makes each load warn "placed N of
# 7 trees": the test counts loads by that line.
sed -e 's|grammar="[^"]*"|grammar="tree.lsys"|' -e 's|min-distance="[^"]*"|min-distance="9"|' \
  "$src/examples/scenes/fireworks.xml" > "$work/scene.xml"
cp "$work/scene.xml" "$work/good.xml"
"$sylva" view "$work/scene.xml" --size 640x360 >"$work/view.out" 2>"$work/view.err" &
viewer=$!
loads() { grep -c "of 7 trees: the area is too small" "$work/view.err" || true; }
errors() { grep -c "the scene has errors" "$work/view.err" || true; }
for _ in $(seq 100); do [[ $(loads) -ge 1 ]] && break; sleep 0.1; done
[[ $(loads) -eq 1 ]] || { cat "$work/view.err"; exit 1; }
sleep 0.5
sed 's|<sky top=|<sky tpo=|' "$work/good.xml" > "$work/next.xml"; mv "$work/next.xml" "$work/scene.xml"
for _ in $(seq 100); do [[ $(errors) -ge 1 ]] && break; sleep 0.1; done
grep -q "scene.xml:5:8: error: unknown attribute 'tpo'" "$work/view.err" || { cat "$work/view.err"; exit 1; }
kill -0 "$viewer"
cp "$work/good.xml" "$work/next.xml"; mv "$work/next.xml" "$work/scene.xml"
for _ in $(seq 100); do [[ $(loads) -ge 2 ]] && break; sleep 0.1; done
[[ $(loads) -ge 2 ]] || { echo "the fixed scene did not load again"; cat "$work/view.err"; exit 1; }
printf 'axiom: A(1)\nA(l) --> F(l*nope)\n' > "$work/tree.lsys"
for _ in $(seq 100); do [[ $(errors) -ge 2 ]] && break; sleep 0.1; done
grep -q "tree.lsys:2:14: error: unknown name 'nope'" "$work/view.err" || { cat "$work/view.err"; exit 1; }
kill -0 "$viewer"
# Fixing the grammar loads the scene again (the failed load still watches it).
n=$(loads)
cp "$src/grammars/abop/fig2_07a_sympodial.lsys" "$work/tree.lsys"
for _ in $(seq 100); do [[ $(loads) -gt $n ]] && break; sleep 0.1; done
[[ $(loads) -gt $n ]] || { echo "the fixed grammar did not load again"; cat "$work/view.err"; exit 1; }
echo "viewer reloaded the scene and its grammar, reported errors and kept running"

# With no file the viewer opens the bundled autumn scene (SCENE.md).
"$sylva" view --screenshot "$work/default.png" --frames 3 --size 480x270 >"$work/default.err" 2>&1
grep -q "at t = 0 s" "$work/default.err" || { echo "no file: not a scene"; cat "$work/default.err"; exit 1; }
[[ -s "$work/default.png" ]]
echo "with no file the viewer opened the bundled scene"
