#!/usr/bin/env bash
# `surfmap fit --json --series` prints each pair's arc length and mu: as many
# as the fit's pairs, in path order, and each piece's mu is the mean of its
# own pairs (DragPiece: first_pair .. first_pair + pairs - 1).
#   fit_series_test.sh SURFMAP SIMTRACE
set -euo pipefail
SURFMAP=$1
SIMTRACE=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$SIMTRACE" --shape plane --material glass --boundary sandpaper --seed 7 >"$dir/drag.csv"
"$SURFMAP" fit --json --series "$dir/drag.csv" >"$dir/fit.json"
python3 - "$dir/fit.json" <<'PY'
import json, sys
fit = json.loads(open(sys.argv[1]).read())
s, mu = fit["pair_s_mm"], fit["pair_mu"]
assert len(s) == len(mu) == fit["n_pairs"], (len(s), len(mu), fit["n_pairs"])
assert all(b >= a for a, b in zip(s, s[1:])), "pair positions decrease"
assert len(fit["pieces"]) == 2, "glass | sandpaper should give two pieces: %d" % len(fit["pieces"])
for piece in fit["pieces"]:
    own = mu[piece["first_pair"]:piece["first_pair"] + piece["pairs"]]
    mean = sum(own) / len(own)
    assert abs(mean - piece["mu"]) < 1e-12, (mean, piece["mu"])
print("fit --series: %d pairs, pieces at mu %s" % (len(mu), [round(p["mu"], 3) for p in fit["pieces"]]))
PY
# Without --series the series is not printed.
"$SURFMAP" fit --json "$dir/drag.csv" | python3 -c 'import json, sys; assert "pair_mu" not in json.loads(sys.stdin.read())'
