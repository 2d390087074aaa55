#!/usr/bin/python3
"""Summarises evolve runs written by table5.sh: OUT/table.md, OUT/ranks.md
(Mann-Whitney U tests of the paper's claims, and of structured mapping's
falls against the hybrid's), OUT/falls.md (falls from
generation 10 on, and the best gaits against the Froude targets) and plots.
Runs not finished yet are left out, and each table says how many it has.

    POPULATION=75 summarise.py OUT_DIR RUNS GRAMMAR...
"""
import csv
import math
import os
import shutil
import subprocess
import sys

import ranktest

PAPER = {  # Murphy, O'Neill and Carr, Tables 4 and 5 (30 runs, 75 x 50)
    "hybrid": (95.3, 5.2729, 138.8273, 57.2904),
    "concatenating": (100.333, 8.5231, 140.9203, 43.1542),
    "sinusoidal": (100.4333, 6.0039, 150.2595, 44.2394),
    "numerical": (101.3333, 8.5715, 132.6506, 37.6833),
    "free": (106.3, 19.05, 279.1248, 81.3519),
    "concatenating_varying_weights": (102.7, 5.3572, 154.5484, 50.3666),
    "concatenating_varying_freedom": (104.0333, 7.8892, 112.2726, 8.4968),
}
NAMES = {
    "hybrid": "Numerical & concatenating functions",
    "concatenating": "Concatenating functions",
    "sinusoidal": "Sinusoidal grammar",
    "numerical": "Numerical only",
    "free": "Free",
    "concatenating_varying_weights": "Concatenating, varying fitness weights",
    "concatenating_varying_freedom": "Concatenating, varying joint freedom",
    "hybrid_structured": "Numerical & concatenating, structured mapping (ours)",
    "numerical_balance": "Numerical only, balance reflex (ours)",
    "hybrid_balance": "Numerical & concatenating, balance reflex (ours)",
    "hybrid_structured_balance": "Numerical & concatenating, structured mapping, balance reflex (ours)",
}


# The horse seed's targets from Fr 0.4 (docs/evolve.md, Fitness): speed m/s,
# stride length m, duty factor.
TARGETS = (1.534, 1.991, 0.67)
SETTLED_FROM = 10  # the generation from which falls are counted against the 20 % goal


def settled_falls(data, population):
    """One run's falls per generation from SETTLED_FROM on, as shares of the
    population."""
    return [int(d["fell"]) / population for d in data if int(d["generation"]) >= SETTLED_FROM]


def falls_row(g, datas, population):
    """Walks that fell from generation SETTLED_FROM on, as a share of the
    population, and the last best gait of each run against TARGETS."""
    shares = [settled_falls(data, population) for data in datas]  # per run, per generation
    gens = min(len(r) for r in shares)
    per_gen = [sum(r[i] for r in shares) / len(shares) for i in range(gens)]
    if not per_gen:
        return None
    worst_run_gen = max(max(r) for r in shares)
    off = []
    for data in datas:
        last = data[-1]
        got = (float(last["best_speed"]), float(last["best_stride_length"]),
               float(last["best_duty_factor"]))
        off.append(max(abs(v - t) / t for v, t in zip(got, TARGETS)))
    measures = [mean_sd([float(d[-1][k]) for d in datas])[0]
                for k in ("best_speed", "best_stride_length", "best_duty_factor")]
    within = sum(1 for o in off if o <= 0.15)
    return (f"| {NAMES.get(g, g)} | {len(datas)} | {100 * sum(per_gen) / gens:.1f} | "
            f"{100 * max(per_gen):.1f} | {100 * worst_run_gen:.1f} | "
            f"{measures[0]:.3f} / {measures[1]:.3f} / {measures[2]:.3f} | {within} of {len(datas)} |")


def mean_sd(xs):
    m = sum(xs) / len(xs)
    sd = math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1)) if len(xs) > 1 else 0.0
    return m, sd


def rank_claims(finals, falls=None):
    """The paper's claims as one-sided Mann-Whitney U tests on the last
    generation's best fitness (lower is better) of every run, among the
    paper's configurations; and, when both hybrid runs are there, whether
    structured mapping falls less (`falls`: grammar -> each run's mean share
    of falls from SETTLED_FROM on)."""
    rows = ["| claim | against | U | p (one-sided) | test | holds at 0.05 |",
            "|---|---|---|---|---|---|"]
    others = lambda g: [o for o in finals if o != g and o in PAPER]
    if "hybrid" in finals:
        for o in others("hybrid"):
            r = ranktest.mann_whitney_u(finals["hybrid"], finals[o])
            rows.append(f"| hybrid best: lower than | {o} | {r['u_a']:.1f} | {r['p_less']:.4f} | "
                        f"{r['method']} | {'yes' if r['p_less'] < 0.05 else 'no'} |")
    if "free" in finals:
        for o in others("free"):
            r = ranktest.mann_whitney_u(finals[o], finals["free"])
            rows.append(f"| free worst: higher than | {o} | {r['u_b']:.1f} | {r['p_less']:.4f} | "
                        f"{r['method']} | {'yes' if r['p_less'] < 0.05 else 'no'} |")
        for o in others("free"):
            r = ranktest.spread_test(finals["free"], finals[o])
            rows.append(f"| free most variable: wider than | {o} | {r['u_b']:.1f} | "
                        f"{r['p_less']:.4f} | {r['method']}, distances from the median | "
                        f"{'yes' if r['p_less'] < 0.05 else 'no'} |")
    falls = falls or {}
    if "hybrid" in falls and "hybrid_structured" in falls:
        r = ranktest.mann_whitney_u(falls["hybrid_structured"], falls["hybrid"])
        rows.append(f"| structured mapping: fewer falls from gen {SETTLED_FROM} than | hybrid | "
                    f"{r['u_a']:.1f} | {r['p_less']:.4f} | {r['method']}, mean falls of a run | "
                    f"{'yes' if r['p_less'] < 0.05 else 'no'} |")
    return "\n".join(rows) + "\n"


def main():
    out, runs, grammars = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
    population = int(os.environ.get("POPULATION", "75"))
    rows = ["| Grammar | runs | Avg. best | Std. dev. | Avg. avg. | Std. dev. | invalid (last gen, "
            "mean) | paper: avg. best (sd) | paper: avg. avg. (sd) |",
            "|---|---|---|---|---|---|---|---|---|"]
    fall_rows = [f"| Grammar | runs | fell from gen {SETTLED_FROM}: mean % | worst generation "
                 "(mean over runs) % | worst generation of a run % | last best gait: speed / "
                 "stride / duty (mean) | best gaits within 15 % of every target |",
                 "|---|---|---|---|---|---|---|"]
    curves = {}
    finals = {}  # grammar -> last generation's best fitness of every run
    run_falls = {}  # grammar -> every run's mean share of falls from SETTLED_FROM on
    for g in grammars:
        best, avg, invalid, per_gen, datas = [], [], [], [], []
        for r in range(1, runs + 1):
            path = os.path.join(out, f"{g}_{r}.csv")
            if not os.path.exists(path):
                continue  # not run yet
            with open(path) as f:
                data = list(csv.DictReader(f))
            datas.append(data)
            best.append(float(data[-1]["best"]))
            avg.append(float(data[-1]["average"]))
            invalid.append(float(data[-1]["invalid"]))
            per_gen.append([(float(d["best"]), float(d["average"])) for d in data])
        if not datas:
            continue
        finals[g] = best
        settled = [x for x in (settled_falls(data, population) for data in datas) if x]
        if settled:  # runs that ended before SETTLED_FROM are left out
            run_falls[g] = [sum(x) / len(x) for x in settled]
        b, bsd = mean_sd(best)
        a, asd = mean_sd(avg)
        p = PAPER.get(g)
        paper = (f"{p[0]} ({p[1]}) | {p[2]} ({p[3]})" if p else "- | -")
        rows.append(f"| {NAMES.get(g, g)} | {len(datas)} | {b:.1f} | {bsd:.1f} | {a:.1f} | "
                    f"{asd:.1f} | {sum(invalid) / len(invalid):.1f} | {paper} |")
        falls = falls_row(g, datas, population)
        if falls:
            fall_rows.append(falls)
        gens = min(len(run) for run in per_gen)
        curves[g] = [(i, sum(run[i][0] for run in per_gen) / len(per_gen),
                      sum(run[i][1] for run in per_gen) / len(per_gen)) for i in range(gens)]
    table = "\n".join(rows) + "\n"
    ranks = rank_claims(finals, run_falls)
    with open(os.path.join(out, "ranks.md"), "w") as f:
        f.write(ranks)
    print(ranks)
    with open(os.path.join(out, "table.md"), "w") as f:
        f.write(table)
    print(table)
    falls = "\n".join(fall_rows) + "\n"
    with open(os.path.join(out, "falls.md"), "w") as f:
        f.write(falls)
    print(falls)
    for g, pts in curves.items():
        with open(os.path.join(out, f"mean_{g}.dat"), "w") as f:
            for i, b, a in pts:
                f.write(f"{i} {b} {a}\n")
    if shutil.which("gnuplot"):
        for col, name in ((2, "best"), (3, "average")):
            plots = ", ".join(f"'{out}/mean_{g}.dat' using 1:{col} with lines lw 2 title '{g}'"
                              for g in curves)
            script = (f"set terminal svg size 800,500; set output '{out}/{name}.svg';"
                      f"set logscale y; set xlabel 'generation'; set ylabel '{name} fitness';"
                      f"set key outside; plot {plots}")
            subprocess.run(["gnuplot", "-e", script], check=True)
        print(f"plots: {out}/best.svg {out}/average.svg")


if __name__ == "__main__":
    main()
