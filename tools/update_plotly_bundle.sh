#!/bin/sh
# Refresh the plotly.js partial bundle the HTML pages embed (src/openmotion/program/vendor):
# plotly.js-gl3d-dist-min (MIT; scatter, scatter3d and the core) from npm, gzipped, with its
# LICENSE and a VERSION line. Usage: tools/update_plotly_bundle.sh [version]; the default
# is the plotly.js version the installed python plotly bundles (so its figure JSON matches).
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
out="$here/src/openmotion/program/vendor"
version=${1:-$(python -c "from plotly.offline import get_plotlyjs; import re; \
print(re.search(r'plotly\.js v(\d+\.\d+\.\d+)', get_plotlyjs()[:200]).group(1))")}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
(cd "$tmp" && npm pack --silent "plotly.js-gl3d-dist-min@$version" >/dev/null)
tar xzf "$tmp"/plotly.js-gl3d-dist-min-*.tgz -C "$tmp"
mkdir -p "$out"
# -n: no name or time stamp in the header, so the same bundle gives the same bytes
gzip -9 -n -c "$tmp/package/plotly-gl3d.min.js" > "$out/plotly-gl3d.min.js.gz"
cp "$tmp/package/LICENSE" "$out/LICENSE"
echo "plotly.js-gl3d-dist-min $version" > "$out/VERSION"
echo "plotly.js-gl3d-dist-min $version -> $out ($(wc -c < "$out/plotly-gl3d.min.js.gz") bytes)"
