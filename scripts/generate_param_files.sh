#!/usr/bin/env bash
# Writes the files generated from the parameter table (ros/localizer_config.cc
# and the core's option tables): config/pf.yaml, cfg/PfLocalization.cfg and the
# manual's parameter table (docs/parameters.md, between its "parameters:begin" and
# "parameters:end" markers). Run it after changing a parameter; test/ros_unit/params/parameter_docs_test.cc
# fails while any of them differs from the table.
#   bash scripts/generate_param_files.sh
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
# shellcheck source=scripts/workspace.bash
source "$repo/scripts/workspace.bash"
ws=$(pf_default_ws "$repo")
bash "$repo/scripts/build.sh" pf_param_docs >/dev/null
docs=$ws/devel/lib/pf_localization/pf_param_docs
"$docs" yaml >"$repo/config/pf.yaml"
"$docs" cfg >"$repo/cfg/PfLocalization.cfg"
table=$(mktemp)
"$docs" markdown >"$table"
/usr/bin/python3 - "$repo/docs/parameters.md" "$table" <<'PY'
import re, sys
page, table = sys.argv[1], open(sys.argv[2]).read()
text = open(page).read()
begin, end = '<!-- parameters:begin -->\n', '<!-- parameters:end -->'
if begin not in text or end not in text:
    sys.exit('generate_param_files: docs/parameters.md has no parameters:begin/end markers')
head, rest = text.split(begin, 1)
_, tail = rest.split(end, 1)
open(page, 'w').write(head + begin + table + end + tail)
PY
rm -f "$table"
echo "generate_param_files: wrote config/pf.yaml, cfg/PfLocalization.cfg and docs/parameters.md's table"
