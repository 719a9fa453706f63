#!/bin/bash
# docs/scene.rng against the example scenes and a scene using every
# attribute (each must validate, and pass `sylva check`), and against small
# scenes with a structural error (each must be refused by both).
# Usage: schema_test.sh SOURCE_DIR WORK_DIR SYLVA
set -u
src=$1
work=$2
sylva=$3
rng=$src/docs/scene.rng
mkdir -p "$work"
command -v xmllint >/dev/null || { echo "xmllint not found (Debian libxml2-utils)"; exit 1; }

fail=0
if ! xmllint --noout --relaxng "$rng" "$src"/examples/scenes/*.xml "$src"/tests/scene/data/*.xml; then
  echo "FAIL: a scene does not match docs/scene.rng"
  fail=1
fi
for f in "$src"/examples/scenes/*.xml "$src"/tests/scene/data/every_attribute.xml; do
  if ! "$sylva" check "$f"; then
    echo "FAIL: sylva check refuses $f"
    fail=1
  fi
done

# Each line: a name, then the body of a <scene version="1"> the schema must
# reject.
while IFS='|' read -r name body; do
  file=$work/$name.xml
  printf '<scene version="1">\n%s\n</scene>\n' "$body" >"$file"
  if xmllint --noout --relaxng "$rng" "$file" 2>/dev/null; then
    echo "FAIL: docs/scene.rng accepts $name: $body"
    fail=1
  fi
  "$sylva" check "$file" 2>/dev/null
  status=$?
  if [ $status -ne 2 ]; then
    echo "FAIL: sylva check exits $status (not 2) on $name: $body"
    fail=1
  fi
done <<'CASES'
unknown_element|<terrain/><forrest grammar="a.lsys" count="3"/>
unknown_attribute|<terrain resolution="65" heigth="3"/>
unknown_child|<particles><emitter/><terrain/></particles>
draw_at_top|<draw/>
bad_enum|<terrain noise="perlin"/>
second_camera|<camera orbit="0 10 5"/><camera orbit="0 10 6"/>
camera_position_and_orbit|<camera position="1 2 3" orbit="0 10 5"/>
point_light_without_position|<light type="point"/>
two_draws|<particles><emitter/><draw/><draw/></particles>
drag_without_k|<particles><emitter/><drag/></particles>
mesh_without_as_mesh|<particles><emitter/><draw as="points" mesh="~leaf"/></particles>
pin_and_pin_ids|<cloth pin="top" pin-ids="0 1"/>
plant_without_grammar|<plant position="0 0"/>
include_with_param|<default name="f" value="a.xml"/><include file="$f"/>
text_inside|<sky>blue</sky>
bad_id|<terrain id="1hill"/>
CASES

# A $parameter stands for any value, enumerated ones included.
printf '<scene version="1"><default name="n" value="ridged"/><terrain noise="$n"/></scene>\n' \
  >"$work/param_enum.xml"
if ! xmllint --noout --relaxng "$rng" "$work/param_enum.xml" || ! "$sylva" check "$work/param_enum.xml"; then
  echo "FAIL: docs/scene.rng refuses a \$parameter in an enumerated attribute"
  fail=1
fi
exit $fail
