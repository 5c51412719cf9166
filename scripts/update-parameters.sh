#!/usr/bin/env bash
# Rewrites the two copies of the world parameter table outside the code from `cps parameters`:
# the world section of assets/schemas/scene.schema.json and the option table of docs/commands.md
# (between its "cps parameters" markers). Run it after changing the table in
# engine/src/parameters.cpp; tests/cli/test_cli_parameters.cpp fails until it has run.
# Usage: scripts/update-parameters.sh [CPS]   (CPS: default build/demos/cps). Needs python3.
set -euo pipefail
cd "$(dirname "$0")/.."
cps=${1:-build/demos/cps}
schema_json=$("$cps" parameters --format schema)
table_md=$("$cps" parameters --format markdown)
SCHEMA_JSON=$schema_json TABLE_MD=$table_md python3 - <<'PY'
import json, os, re

# The schema keeps its hand layout: the world definition is written one property a line.
world = json.loads(os.environ["SCHEMA_JSON"])
path = "assets/schemas/scene.schema.json"
text = open(path, encoding="utf-8").read()
start = text.index('    "world": {\n')
end = text.index('\n    },\n', start) + len('\n    },\n')
lines = ['    "world": {']
for key in ("type", "additionalProperties", "description"):
    lines.append('      %s: %s,' % (json.dumps(key), json.dumps(world[key], ensure_ascii=False)))
lines.append('      "properties": {')
props = list(world["properties"].items())
for i, (key, node) in enumerate(props):
    comma = "," if i + 1 < len(props) else ""
    lines.append('        %s: %s%s' % (json.dumps(key), json.dumps(node, ensure_ascii=False), comma))
lines += ['      }', '    },', '']
text = text[:start] + "\n".join(lines) + text[end:]
json.loads(text)  # still one valid document
open(path, "w", encoding="utf-8").write(text)

path = "docs/commands.md"
text = open(path, encoding="utf-8").read()
begin, stop = "<!-- BEGIN cps parameters -->\n", "<!-- END cps parameters -->"
b = text.index(begin) + len(begin)
e = text.index(stop, b)
text = text[:b] + os.environ["TABLE_MD"] + "\n" + text[e:]
open(path, "w", encoding="utf-8").write(text)
PY
echo "update-parameters.sh: wrote assets/schemas/scene.schema.json (world) and docs/commands.md"
