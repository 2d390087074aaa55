#!/usr/bin/env python3
"""Neighbours of the horse's balanced seed walk, for the balance reflex on
the runtime (docs/results/balance_runtime.md).

Usage: balance_neighbours.py SEED_GAIT OUT_DIR COUNT RNG_SEED [FRACTION]

Writes OUT_DIR/n<i>.yaml (with the seed's balance:) and OUT_DIR/n<i>_plain.yaml
(without it): every constant, amplitude and phase of every curve moved by up
to FRACTION (default 0.25, the numerical grammar's range) of itself, the
harmonics and the 2*PI kept, as the fitness test's near neighbours are drawn.
"""

import pathlib
import random
import re
import sys

NUMBER = re.compile(r"-?\d+(?:\.\d+)?")


def neighbour_curve(curve, fraction, rng):
    out, last = [], 0
    for m in NUMBER.finditer(curve):
        out.append(curve[last:m.start()])
        harmonic = curve[max(0, m.start() - 4):m.start()] == "sin("
        two_pi = curve[m.end():m.end() + 3] == "*PI"
        value = m.group(0)
        if not (harmonic or two_pi):
            value = "%.6g" % (float(value) * (1.0 + fraction * (2.0 * rng.random() - 1.0)))
        out.append(value)
        last = m.end()
    out.append(curve[last:])
    return "".join(out)


def main():
    seed_path, out_dir, count, rng_seed = sys.argv[1:5]
    fraction = float(sys.argv[5]) if len(sys.argv) > 5 else 0.25
    rng = random.Random(int(rng_seed))
    lines = pathlib.Path(seed_path).read_text().splitlines()
    out = pathlib.Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    for n in range(int(count)):
        body, in_curves = [], False
        for line in lines:
            if line.startswith("curves:"):
                in_curves = True
            elif line and not line.startswith(" "):
                in_curves = False
            curve = re.match(r'^(\s+\w+: ")(.*)(")$', line) if in_curves else None
            body.append(curve.group(1) + neighbour_curve(curve.group(2), fraction, rng) +
                        curve.group(3) if curve else line)
        text = "\n".join(body) + "\n"
        (out / f"n{n}.yaml").write_text(text)
        plain = "\n".join(l for l in body if not l.startswith("balance:")) + "\n"
        (out / f"n{n}_plain.yaml").write_text(plain)


if __name__ == "__main__":
    main()
