#!/usr/bin/python3
"""Writes the seed gaits and the GE grammars of the gait-evolution runs.

    /usr/bin/python3 scripts/experiments/make_grammars.py   (from the repository root)

Outputs (checked in; rerun after changing the seed data below):
  configs/gaits/horse_seed.yaml, configs/gaits/quadruped_seed.yaml
  configs/grammars/{horse,quadruped}_{numerical,concatenating,hybrid,sinusoidal,free}.bnf

Grammar styles (after Murphy, O'Neill and Carr, "Exploring Grammatical
Evolution for Horse Gait Optimisation"):
  numerical      every seed term's amplitude, frequency and phase (and the
                 constant) chosen within 25 % of its seed value
  concatenating  the seed curve plus appended sine/cosine functions (Fig. 2)
  hybrid         numerical seed terms plus appended functions
  sinusoidal     appended functions only, no seed data ("free-style sinusoidal")
  free           arithmetic, sin and cos over t, no seed data (Fig. 5)
A phenotype is one curve per line of the seed gait, separated by ';' (the
<newline> rule), each an expression of animrt's gait expression language.
"""

import math
import os

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# Terms whose amplitude is below this (degrees) are dropped, as the paper
# drops Fourier terms below its threshold of 1.
THRESHOLD = 1.0
HALF_PI = 1.5708

# ---- horse seed data -------------------------------------------------------
# Each curve: (constant, [(amplitude_deg, harmonic, phase_rad), ...]) in
# degrees of joint angle away from the straight leg of configs/models/horse.xml
# (positive turns the distal segment forward), t in stride cycles with t = 0
# mid-swing of that limb.
#
# Where the numbers come from: the ranges of motion of the walk reported in
# the equine kinematics literature summarised by Back and Clayton, "Equine
# Locomotion" (2001), rounded (scapula about 20 deg, shoulder 25, elbow 55,
# carpus 70, fore fetlock 80, hip 30, stifle 35, tarsus 35, hind fetlock 70;
# the head and neck nod twice per stride by a few degrees). We did not have
# the published angle-time plots, so the curves are not Fourier fits of
# measured data: each is built from one to three harmonics with the phase
# relations of a walk (proximal joints swing sinusoidally, distal joints flex
# in mid-swing, the fetlock extends in stance). Distal ranges are reduced by
# about half (elbow 30, carpus 50, fetlocks 40) because the model's legs are
# straight at rest and a full-range carpus folds the leg under it. The small
# terms listed below the threshold stand for the higher harmonics a Fourier
# fit would find; they are dropped, as in the paper.
HORSE = [
    ("scapula", 0.0, [(10.0, 1, 0.0), (1.5, 2, 1.0), (0.6, 3, 0.4)]),
    ("shoulder", 0.0, [(12.0, 1, -0.3), (2.0, 2, 0.8), (0.5, 3, 2.0)]),
    ("elbow", 12.0, [(15.0, 1, HALF_PI), (3.0, 2, HALF_PI), (0.7, 3, 0.2)]),
    ("carpal", -20.0, [(25.0, 1, -HALF_PI), (8.0, 2, -HALF_PI), (0.8, 4, 1.1)]),
    ("fore_fetlock", -10.0, [(20.0, 1, -HALF_PI), (2.5, 2, 0.6), (0.4, 3, 1.9)]),
    ("hip", 0.0, [(12.0, 1, 0.0), (1.8, 2, 0.9), (0.5, 3, -0.7)]),
    ("stifle", -8.0, [(12.0, 1, -HALF_PI), (3.0, 2, -HALF_PI), (0.6, 3, 0.3)]),
    ("tarsal", 8.0, [(12.0, 1, HALF_PI), (3.0, 2, HALF_PI), (0.9, 3, -1.2)]),
    ("hind_fetlock", -10.0, [(18.0, 1, -HALF_PI), (2.2, 2, 0.5), (0.3, 4, 0.0)]),
    ("neck_proximal", 0.0, [(3.0, 2, 0.5), (0.6, 1, 0.0)]),
    ("neck_mid", 0.0, [(2.5, 2, 1.0), (0.5, 1, 0.3)]),
    ("atlas", 0.0, [(4.0, 2, 1.5), (0.8, 1, -0.4)]),
]
HORSE_JOINTS = [
    # robot joint, curve, limb
    *[(f"{s}_{j}", c, s) for s in ("lf", "rf") for j, c in
      [("scapula", "scapula"), ("shoulder", "shoulder"), ("elbow", "elbow"),
       ("carpal", "carpal"), ("fetlock", "fore_fetlock")]],
    *[(f"{s}_{j}", c, s) for s in ("lh", "rh") for j, c in
      [("hip", "hip"), ("stifle", "stifle"), ("tarsal", "tarsal"), ("fetlock", "hind_fetlock")]],
    ("neck_proximal", "neck_proximal", "neck"),
    ("neck_mid", "neck_mid", "neck"),
    ("atlas", "atlas", "neck"),
]
# Lateral-sequence walk: each limb a quarter stride after the previous.
HORSE_LIMBS = [("lh", 0.0), ("lf", 0.25), ("rh", 0.5), ("rf", 0.75), ("neck", 0.0)]
# Fr = v / sqrt(g h) = 0.4 at h = 1.5 m: 1.53 m/s, 2.0 m strides at 0.77 Hz,
# a brisk walk.
HORSE_FROUDE = (0.4, 1.5)

# ---- demo quadruped seed: the curves of configs/gaits/walk.yaml -----------
QUAD = [
    ("hip", 2.5, [(18.0, 1, -1.07), (3.2, 2, 2.97)]),
    ("knee", -20.0, [(14.0, 1, 0.6), (5.5, 2, -0.4)]),
    ("ankle", 12.0, [(10.5, 1, 2.2), (4.0, 2, 1.3), (1.5, 3, -2.5)]),
]
QUAD_JOINTS = [(f"{s}_{j}", j, s) for s in ("lf", "rf", "lh", "rh") for j in ("hip", "knee", "ankle")]
QUAD_LIMBS = [("lh", 0.0), ("lf", 0.25), ("rh", 0.5), ("rf", 0.75)]
# Fr 0.06 at h = 0.18 m: 0.08 m/s, 0.077 m strides at 1.04 Hz, about the
# 1 Hz of walk.yaml (a slow walk; the light model slips at faster ones).
QUAD_FROUDE = (0.06, 0.18)


def num(v):
    s = f"{v:.4f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def kept(terms):
    return [t for t in terms if abs(t[0]) >= THRESHOLD]


def seed_expression(const, terms):
    out = num(const)
    for a, k, p in kept(terms):
        out += f" + {num(a)}*sin({k}*2*PI*t + {num(p)})"
    return out


def range_rule(value, fraction=0.25, steps=5):
    """`lo | lo+s | ... | hi` around value (+-fraction), as a compact range."""
    if abs(value) < 1e-9:
        s = 0.05  # a zero seed value still gets a small window
    else:
        s = round(fraction * abs(value) / steps, 4)
    lo = round(value - steps * s, 4)
    return f"{num(lo)} | {num(lo + s)} | ... | {num(round(value + steps * s, 4))}"


FUNCS = """
<funcs> ::= <funcs> <op> <funcs>
          | <function>
          | <med_amp_var>

<op> ::= + | -

<function> ::= <low_amp_var>*sin(<low_freq_var>*2*PI*t)
             | <low_amp_var>*cos(<low_freq_var>*2*PI*t)
             | <med_amp_var>*sin(<med_freq_var>*2*PI*t)
             | <med_amp_var>*cos(<med_freq_var>*2*PI*t)
             | <hi_amp_var>*sin(<hi_freq_var>*2*PI*t)
             | <hi_amp_var>*cos(<hi_freq_var>*2*PI*t)

# Harmonics of the stride (t is in stride cycles).
<low_freq_var> ::= 1 | 2
<med_freq_var> ::= 3 | 4
<hi_freq_var> ::= 5 | 6 | 7 | 8

# Degrees. Higher harmonics get smaller amplitudes (the paper's ranges).
<low_amp_var> ::= 0 | 0.25 | ... | 20
<med_amp_var> ::= 0 | 0.1 | ... | 4
<hi_amp_var> ::= 0 | 0.05 | ... | 1
"""

FREE = """
<expr> ::= <expr> <op> <expr>
         | (<expr> <op> <expr>)
         | <pre-op>(<expr> * t)
         | <var>

<op> ::= + | - | / | *
<pre-op> ::= sin | cos
<var> ::= t | <const>
<const> ::= 0.5 | 1 | ... | 20
"""


def header(model, style, curves):
    names = ", ".join(c[0] for c in curves)
    return (f"# {style} grammar for the {model} (written by scripts/experiments/make_grammars.py).\n"
            f"# One curve per seed-gait curve, in this order: {names}.\n")


def prog(n, rule="fcurve", shared=False):
    parts = [f"<{rule}>" if shared else f"<{rule}{i}>" for i in range(n)]
    return "<prog> ::= " + " <newline> ".join(parts) + "\n<newline> ::= ;\n"


def numerical_rules(curves):
    out = ""
    for i, (name, const, terms) in enumerate(curves):
        body = f"<c{i}_k>"
        rules = f"<c{i}_k> ::= {range_rule(const)}\n"
        for j, (a, k, p) in enumerate(kept(terms)):
            body += f" + <c{i}_a{j}>*sin(<c{i}_f{j}>*2*PI*t + <c{i}_p{j}>)"
            rules += f"<c{i}_a{j}> ::= {range_rule(a)}\n"
            rules += f"<c{i}_f{j}> ::= {range_rule(float(k))}\n"
            rules += f"<c{i}_p{j}> ::= {range_rule(p)}\n"
        out += f"# {name}\n<ncurve{i}> ::= {body}\n{rules}"
    return out


def grammar(model, style, curves):
    n = len(curves)
    g = header(model, style, curves)
    if style == "concatenating":
        g += prog(n)
        for i in range(n):
            g += f"<fcurve{i}> ::= <curve{i}> | <curve{i}> + <funcs>\n"
        g += FUNCS + "\n# Seed data\n"
        for i, (name, const, terms) in enumerate(curves):
            g += f"<curve{i}> ::= {seed_expression(const, terms)}\n"
    elif style == "numerical":
        g += prog(n, "ncurve") + "\n" + numerical_rules(curves)
    elif style == "hybrid":
        g += prog(n)
        for i in range(n):
            g += f"<fcurve{i}> ::= <ncurve{i}> | <ncurve{i}> + <funcs>\n"
        g += FUNCS + "\n# Seed data, each term within 25 %\n" + numerical_rules(curves)
    elif style == "sinusoidal":
        g += prog(n, shared=True) + "<fcurve> ::= <funcs>\n" + FUNCS
    elif style == "free":
        g += prog(n, shared=True) + "<fcurve> ::= <expr>\n" + FREE
    return g


def gait_yaml(name, comment, curves, froude, limbs, joints):
    out = comment + f"\nname: {name}\n\nfroude: {{number: {froude[0]}, hip_height_m: {froude[1]}}}\n\ncurves:\n"
    for cname, const, terms in curves:
        out += f'  {cname}: "{seed_expression(const, terms)}"\n'
    out += "\nlimbs:\n" + "".join(f"  {l}: {p}\n" for l, p in limbs)
    out += "\njoints:\n" + "".join(f"  {j}: {{curve: {c}, limb: {l}}}\n" for j, c, l in joints)
    return out


HORSE_COMMENT = """# Seed walk of the horse model (configs/models/horse.xml), written by
# scripts/experiments/make_grammars.py: where each number comes from is
# explained there. Curves are in degrees away from the straight leg, t in
# stride cycles; left and right legs share a curve half a stride apart.
# Terms below 1 degree of amplitude were dropped."""

QUAD_COMMENT = """# Seed walk of the demo quadruped for gait evolution: the curves of
# configs/gaits/walk.yaml with Froude timing (the fitness targets come from
# the Froude number). Written by scripts/experiments/make_grammars.py."""


def main():
    with open(os.path.join(ROOT, "configs/gaits/horse_seed.yaml"), "w") as f:
        f.write(gait_yaml("horse_seed", HORSE_COMMENT, HORSE, HORSE_FROUDE, HORSE_LIMBS, HORSE_JOINTS))
    with open(os.path.join(ROOT, "configs/gaits/quadruped_seed.yaml"), "w") as f:
        f.write(gait_yaml("quadruped_seed", QUAD_COMMENT, QUAD, QUAD_FROUDE, QUAD_LIMBS, QUAD_JOINTS))
    for model, curves in (("horse", HORSE), ("quadruped", QUAD)):
        for style in ("numerical", "concatenating", "hybrid", "sinusoidal", "free"):
            with open(os.path.join(ROOT, f"configs/grammars/{model}_{style}.bnf"), "w") as f:
                f.write(grammar(model, style, curves))


if __name__ == "__main__":
    main()
