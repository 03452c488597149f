#!/usr/bin/env python3
"""Writes seeded tiny LCPs (mlcp-problem/1, dense A) of n = 5, 10, 20 rows to DIR, for the per-solve
overhead comparison of tests/bench/siconos_bench --repeat: A = G G^T / n + I (positive definite),
b uniform in [-1, 1] (about half the rows active at the answer).

    tiny_lcps.py DIR
"""
import json
import random
import sys


def lcp(n, rng):
    g = [[rng.uniform(-1, 1) for _ in range(n)] for _ in range(n)]
    a = [[sum(g[i][k] * g[j][k] for k in range(n)) / n + (1.0 if i == j else 0.0)
          for j in range(n)] for i in range(n)]
    return {"format": "mlcp-problem/1", "n": n, "A": a,
            "b": [rng.uniform(-1, 1) for _ in range(n)],
            "lo": [0.0] * n, "hi": ["inf"] * n, "findex": [-1] * n}


def main():
    out = sys.argv[1]
    rng = random.Random(48)
    for n in (5, 10, 20):
        with open(f"{out}/tiny_lcp_{n}.json", "w") as f:
            json.dump(lcp(n, rng), f)


if __name__ == "__main__":
    main()
