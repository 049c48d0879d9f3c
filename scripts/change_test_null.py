#!/usr/bin/env python3
"""The split test's false-alarm level, measured: the largest AR(2) likelihood
ratio over a drag's candidate splits when there is no change.

server/estimate/change_points.cc keeps a split when LR exceeds the chi-square(4)
quantile at false_alarm_probability / candidates (Bonferroni). Neighbouring
candidates are strongly correlated, so that bound is usually conservative; this
script simulates one-material series (seeded) and prints the measured quantiles
of max LR beside the Bonferroni value, to check whether the critical value
could be lowered. Usage:

    python3 scripts/change_test_null.py [--pairs 160] [--runs 30000]

Texture models: white noise, and the AR(2) of the simulator's rubber and
masonite (clients/sim/dragsim/material.cc). Needs only numpy.
"""
import argparse
import math

import numpy as np

MODELS = {"white": (0.0, 0.0), "rubber": (0.60, 0.25), "masonite": (1.61, -0.73)}


def chi2_4_sf(c):
    """P(chi-square(4) > c) = exp(-c/2) (1 + c/2)."""
    return math.exp(-c / 2) * (1 + c / 2)


def chi2_4_isf(p):
    lo, hi = 0.0, 200.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if chi2_4_sf(mid) > p else (lo, mid)
    return 0.5 * (lo + hi)


def max_ratio(x, min_pairs):
    """Largest LR over splits k with >= min_pairs on each side (all k)."""
    n = len(x)
    x = x - x.mean()
    y, z1, z2 = x[2:], x[1:-1], x[:-2]
    rows = np.stack([np.ones_like(y), z1, z2, z1 * z1, z2 * z2, z1 * z2, y, y * z1, y * z2, y * y], 1)
    prefix = np.vstack([np.zeros(10), np.cumsum(rows, 0)])

    def sums(a, b):  # rows t in [a + 2, b)
        return prefix[b - 2] - prefix[a]

    def rss(s):
        m = s[..., 0]
        a = s[..., 3] - s[..., 1] ** 2 / m
        c = s[..., 4] - s[..., 2] ** 2 / m
        b = s[..., 5] - s[..., 1] * s[..., 2] / m
        b1 = s[..., 7] - s[..., 6] * s[..., 1] / m
        b2 = s[..., 8] - s[..., 6] * s[..., 2] / m
        yy = s[..., 9] - s[..., 6] ** 2 / m
        det = a * c - b * b
        return yy - ((c * b1 - b * b2) * b1 + (a * b2 - b * b1) * b2) / det, m

    ks = np.arange(min_pairs, n - min_pairs + 1)
    left = np.stack([sums(0, k) for k in ks])
    right = np.stack([sums(k, n) for k in ks])
    r1, n1 = rss(left)
    r2, n2 = rss(right)
    r, m = rss(left + right)
    ratio = m * np.log(r / m) - n1 * np.log(r1 / n1) - n2 * np.log(r2 / n2)
    return ratio.max(), len(ks)


def ar2(rng, n, a1, a2, burn=200):
    e = rng.normal(0.0, 1.0, n + burn)
    x = np.zeros(n + burn)
    for t in range(2, n + burn):
        x[t] = a1 * x[t - 1] + a2 * x[t - 2] + e[t]
    return x[burn:]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--pairs", type=int, default=160, help="series length (a 16 mm window: 160 pairs)")
    parser.add_argument("--min-pairs", type=int, default=15, help="shortest side (1.5 mm)")
    parser.add_argument("--runs", type=int, default=30000)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    print(f"{'texture':10s} {'alpha':>7s} {'measured':>9s} {'Bonferroni':>10s}")
    for name, (a1, a2) in MODELS.items():
        maxima = []
        for _ in range(args.runs):
            m, candidates = max_ratio(ar2(rng, args.pairs, a1, a2), args.min_pairs)
            maxima.append(m)
        maxima = np.array(maxima)
        for alpha in (1e-2, 1e-3):
            print(f"{name:10s} {alpha:7.0e} {np.quantile(maxima, 1 - alpha):9.2f} "
                  f"{chi2_4_isf(alpha / candidates):10.2f}")


if __name__ == "__main__":
    main()
