#!/usr/bin/env bash
# The viewer driven by synthesized mouse and keys (X Test, tests/app/xinput.py)
# in a real window under Xvfb, on a cpfg object in a parallel view:
#  - P held for several frames writes one screenshot;
#  - the wheel zooms a parallel view (the plant's height on screen times
#    0.9^3 after three clicks toward the user);
#  - a drag that starts on the panel moves the panel, never the camera;
#  - F (frame all) frames the plant again in the same parallel projection:
#    the first frame's picture;
#  - a drag off the panel orbits;
#  - an edit of the view file reloads the plant (wider branches);
#  - a 2D figure's `5 pixels` line stays 5 pixels wide after zooming in
#    (re-tessellated for the view);
#  - the panel's reset, step and play buttons show the axiom, step 1 and
#    (by themselves) the last step.
# Usage: viewer_input_test.sh SYLVA_BINARY SOURCE_DIR WORK_DIR
set -euo pipefail
sylva="$(realpath "$1")"; src="$(realpath "$2")"; work="$3"
rm -rf "$work"; mkdir -p "$work/shots" "$work/px"
display=":$((200 + $$ % 500))"
Xvfb "$display" -screen 0 1280x800x24 -nolisten tcp >"$work/xvfb.log" 2>&1 &
xvfb=$!
viewer=""
cleanup() { [[ -n "$viewer" ]] && kill "$viewer" 2>/dev/null; kill "$xvfb" 2>/dev/null; true; }
trap cleanup EXIT
export DISPLAY="$display"
for _ in $(seq 50); do [[ -e "/tmp/.X11-unix/X${display#:}" ]] && break; sleep 0.1; done

X() { python3 "$src/tests/app/xinput.py" "$@"; }
# Pixels of a screenshot right of the panel that differ from its top-right
# corner (the background), and the box around them.
measure() {
  python3 - "$1" "$src/tests/app" <<'PY'
import sys; sys.dont_write_bytecode = True; sys.path.insert(0, sys.argv[2]); import png_rows as png
w, h, rows = png.read(sys.argv[1]); bg = rows[0][4 * (w - 1):4 * (w - 1) + 3]
pts = [(x, y) for y in range(h) for x in range(360, w)
       if sum(abs(rows[y][4 * x + c] - bg[c]) for c in range(3)) > 30]
print(len(pts))
PY
}

# The viewer writes sylva-screenshot-N.png into its working folder.
dir=""
count() { find "$dir" -name 'sylva-screenshot-*.png' | wc -l; }
# Holds P for 0.6 s (several frames) over the window: exactly one more
# screenshot, whose path is printed. A press the viewer never saw (a frame
# longer than the press, on a loaded machine) is tried again, up to 3 times.
shoot() {
  local before after
  before=$(count)
  for _ in 1 2 3; do
    X move 700 300 key p 0.6
    for _ in $(seq 50); do [[ $(count) -gt $before ]] && break; sleep 0.1; done
    [[ $(count) -gt $before ]] && break
  done
  sleep 0.5
  after=$(count)
  if [[ $after -ne $((before + 1)) ]]; then
    echo "P held 0.6 s wrote $((after - before)) screenshots" >&2
    return 1
  fi
  echo "$dir/sylva-screenshot-$after.png"
}
# Starts the viewer on $1 in $dir and waits (at most a minute) for a
# screenshot that shows the plant; sets $shot to its path.
shot=""
start() {
  (cd "$dir" && exec "$sylva" view "$1" --size 960x540) >"$dir/out" 2>"$dir/err" &
  viewer=$!
  for _ in $(seq 60); do
    X move 700 300 key p 0.3 sleep 0.7
    [[ $(count) -gt 0 ]] && break
    kill -0 "$viewer"
  done
  shot="$dir/sylva-screenshot-$(count).png"
  for _ in $(seq 30); do
    [[ $(measure "$shot") -gt 1000 ]] && break
    shot=$(shoot)
  done
}

cat >"$work/plant.l" <<'EOF'
axiom: F(4) [&(40) F(3) [+(50) F(2)]] [^(35) /(90) F(3)] [+(60) &(30) F(2.5)] [-(50) ^(20) F(2)]
EOF
cat >"$work/plant.v" <<'EOF'
initial line width: 0.4
viewpoint: 3,1,2
view reference point: 0,2,0
projection: parallel
EOF
dir="$work/shots"
start "$work/plant.l"
first="$shot"
zoomed=$(X move 700 300 scroll -3 sleep 0.5 && shoot)
# A drag from the panel's body down 170 pixels: ImGui moves the panel.
panel=$(X move 150 180 sleep 0.3 down 1 sleep 0.3 move 150 250 sleep 0.3 move 150 350 sleep 0.3 \
          up 1 sleep 0.5 && shoot)
framed=$(X move 700 300 key f 0.2 sleep 0.5 && shoot)
orbited=$(X move 700 300 sleep 0.3 down 1 sleep 0.3 move 730 300 sleep 0.3 move 760 300 sleep 0.3 \
            up 1 sleep 0.5 && shoot)
sed -i 's/initial line width: 0.4/initial line width: 0.8/' "$work/plant.v"
before=$(measure "$orbited")
reloaded=""
for _ in $(seq 20); do
  reloaded=$(shoot)
  [[ $(measure "$reloaded") -gt $((before * 3 / 2)) ]] && break
done
kill "$viewer"; wait "$viewer" 2>/dev/null || true; viewer=""

# A 2D figure of 5-pixel lines, zoomed in three clicks.
printf 'axiom: F(10)\n' >"$work/px.l"
printf 'initial line width: 5 pixels\n' >"$work/px.v"
dir="$work/px"
start "$work/px.l"
line="$shot"
lineZoomed=$(X move 700 300 scroll 3 sleep 1.5 && shoot)
kill "$viewer"; wait "$viewer" 2>/dev/null || true; viewer=""

# play, step and reset (the panel's buttons, clicked): a binary tree of 6
# steps drawn as lines.
printf 'derivation length: 6\nangle: 30\naxiom: A\nA --> F(1)[+A][-A]\n' >"$work/grow.lsys"
mkdir -p "$work/grow"
dir="$work/grow"
start "$work/grow.lsys"
grown="$shot"
click() { X move "$1" "$2" sleep 0.3 down 1 sleep 0.3 up 1 sleep 0.3 move 700 300 sleep 1; }
click 127 87  # reset: the axiom
reset=$(shoot)
click 80 87  # step: step 1
stepped=$(shoot)
click 35 87  # play: steps 2 to 6 by themselves, at most 4 a second
sleep 3
played=$(shoot)
kill "$viewer"; wait "$viewer" 2>/dev/null || true; viewer=""
python3 - "$src/tests/app" "$grown" "$reset" "$stepped" "$played" <<'PY'
import sys; sys.dont_write_bytecode = True; sys.path.insert(0, sys.argv[1]); import png_rows as png
def dark(path):
    w, h, rows = png.read(path)
    return sum(1 for y in range(h) for x in range(360, w) if sum(rows[y][4 * x:4 * x + 3]) < 3 * 200)
grown, reset, stepped, played = (dark(p) for p in sys.argv[2:])
print(f'line pixels: step 6 {grown}, reset {reset}, step {stepped}, play {played}')
assert reset == 0, 'reset should show the axiom A, which draws nothing'
assert 0 < stepped < grown / 4, 'step should show step 1: one segment'
assert abs(played - grown) <= grown * 0.02, 'play should run to the last step'
PY

python3 - "$src/tests/app" "$first" "$zoomed" "$panel" "$framed" "$orbited" "$reloaded" \
  "$line" "$lineZoomed" <<'PY'
import sys; sys.dont_write_bytecode = True; sys.path.insert(0, sys.argv[1]); import png_rows as png
first, zoomed, panel, framed, orbited, reloaded, line, line_zoomed = sys.argv[2:]
PANEL = 360

def mask(path):
    w, h, rows = png.read(path)
    bg = rows[0][4 * (w - 1):4 * (w - 1) + 3]
    return {(x, y) for y in range(h) for x in range(PANEL, w)
            if sum(abs(rows[y][4 * x + c] - bg[c]) for c in range(3)) > 30}

def height(m):
    ys = [y for _, y in m]
    return max(ys) - min(ys) + 1

def differ(a, b):
    return len(a ^ b) / max(len(a | b), 1)

m = {name: mask(path) for name, path in
     [('first', first), ('zoomed', zoomed), ('panel', panel), ('framed', framed),
      ('orbited', orbited), ('reloaded', reloaded)]}
ratio = height(m['zoomed']) / height(m['first'])
print(f'plant {height(m["first"])} px high, {height(m["zoomed"])} px after 3 wheel clicks '
      f'(ratio {ratio:.3f}, 0.9^3 = 0.729)')
assert abs(ratio - 0.729) < 0.03, 'the wheel does not zoom the parallel view'
d = differ(m['panel'], m['zoomed'])
print(f'a drag on the panel: {100 * d:.2f} % of the plant pixels changed')
assert d < 0.01, 'a drag that starts on the panel turned the view'
d = differ(m['framed'], m['first'])
print(f'frame all: {100 * d:.2f} % of the plant pixels differ from the first frame')
assert d < 0.02, 'frame all does not frame the plant as the first frame did'
d = differ(m['orbited'], m['framed'])
print(f'a drag off the panel: {100 * d:.2f} % of the plant pixels changed')
assert d > 0.2, 'a drag off the panel did not orbit'
print(f'view file edited (width 0.4 -> 0.8): {len(m["orbited"])} -> {len(m["reloaded"])} pixels')
assert len(m['reloaded']) > 1.5 * len(m['orbited']), 'the view file edit was not reloaded'

def line_width(path):
    w, h, rows = png.read(path)
    row = rows[h // 2]
    return sum(1 for x in range(PANEL, w) if sum(row[4 * x:4 * x + 3]) < 3 * 200)

a, b = line_width(line), line_width(line_zoomed)
print(f'a `5 pixels` line: {a} px wide, {b} px after zooming in 3 clicks')
assert 4 <= a <= 6 and 4 <= b <= 6, 'pixel widths do not stay pixels as the view zooms'
PY
echo "the viewer's mouse, keys, frame all and reload work in a parallel view"
