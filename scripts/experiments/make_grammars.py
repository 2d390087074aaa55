#!/usr/bin/python3
"""Writes the seed gaits and the GE grammars of the gait-evolution runs.

    /usr/bin/python3 scripts/experiments/make_grammars.py   (from the repository root)

Outputs (checked in; rerun after changing the seed data below):
  configs/gaits/horse_seed.yaml, configs/gaits/horse_walk.yaml (the seed for
  the runtime), configs/robots/horse.yaml (the horse as a robot playing
  it), configs/gaits/quadruped_seed.yaml
  configs/grammars/{horse,quadruped}_{numerical,concatenating,hybrid,sinusoidal,free}.bnf

Grammar styles (after Murphy, O'Neill and Carr, "Exploring Grammatical
Evolution for Horse Gait Optimisation"):
  numerical      every seed term's amplitude and phase (and the constant)
                 chosen within 25 % of its seed value, its frequency among
                 the whole harmonics within 25 % of its own
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
# The leg curves are designed for the model's geometry, as a walking robot's
# are: each foot follows a path in its hip's frame, and the joint angles come
# from inverse kinematics of the model's segment lengths. An earlier seed
# built from rounded ranges of motion of real horses (Back and Clayton,
# "Equine Locomotion", 2001) fell in 9 of 10 walks on this model: its carpus
# flexed against the model's range and its hind stance began in protraction
# (docs/evolve.md).
#
# The foot path: a stance of HORSE_DUTY of the cycle in which the foot moves
# straight back by HORSE_STRIDE * HORSE_DUTY at a constant height (the body
# moves HORSE_STRIDE per cycle), centred under the hip; a swing that brings it
# forward on a half-cosine, lifted HORSE_LIFT on a half-sine. The body is
# carried HORSE_CROUCH below full leg length, so the leg reaches the ends of
# the stance without locking straight. The hoof stays level.
#
# Inverse kinematics, each leg as two links:
#   fore  scapula and humerus as one link (shoulder held at 0), radius and
#         cannon as the other (carpus held at 0); the elbow is the knee and
#         flexes forward, as a horse's does; the fetlock keeps the pastern
#         vertical.
#   hind  femur and cannon stay parallel (tarsal = -stifle), as a horse's
#         reciprocal apparatus couples stifle and hock, so the leg is a
#         two-link chain of femur + cannon (0.85 m) and tibia (0.45 m); the
#         stifle flexes backward; the fetlock keeps the pastern vertical.
# Each curve is then written as its Fourier series up to HORSE_HARMONICS
# (terms under THRESHOLD dropped). Fewer harmonics leave ripples of a few
# centimetres in the stance path, and rigid legs then bounce from foot to
# foot: with 4 harmonics every walk fell, with 8 none did.
HORSE_STRIDE = 1.8      # m per cycle: 1.39 m/s at 0.77 Hz, 90 % of the Froude speed
HORSE_DUTY = 0.8        # designed; the measured duty is lower (feet land late, lift early)
HORSE_CROUCH = 0.25     # m below full leg length
HORSE_LIFT = 0.15       # m
HORSE_HARMONICS = 8
HORSE_FORE = (0.65, 0.75, 1.6)   # upper link, lower link, attachment to sole (m)
HORSE_HIND = (0.85, 0.45, 1.5)
HORSE_PASTERN = 0.2     # fetlock joint to sole (m)


def horse_foot(s):
    """Foot position (forward, height above stance, 0..1 of swing) at phase s."""
    d, ls = HORSE_DUTY, HORSE_STRIDE * HORSE_DUTY
    s0 = 0.5 - d / 2
    if s0 <= s < s0 + d:
        return ls / 2 - ls * (s - s0) / d, 0.0
    u = ((s - s0 - d) % 1.0) / (1 - d)
    return -ls / 2 + ls * (1 - math.cos(math.pi * u)) / 2, HORSE_LIFT * math.sin(math.pi * u)


def two_link(x, z, l1, l2, knee_sign):
    """Segment angle of the upper link from vertical and knee angle (rad) that put the
    chain's end at (x forward, z down negative)."""
    c = (x * x + z * z - l1 * l1 - l2 * l2) / (2 * l1 * l2)
    q2 = knee_sign * math.acos(max(-1.0, min(1.0, c)))
    q1 = math.atan2(x, -z) - math.atan2(l2 * math.sin(q2), l1 + l2 * math.cos(q2))
    return q1, q2


def horse_leg_angles(s):
    x, lift = horse_foot(s)
    out = {}
    l1, l2, full = HORSE_FORE
    q1, q2 = two_link(x, -(full - HORSE_CROUCH) + lift + HORSE_PASTERN, l1, l2, +1)
    out.update(scapula=q1, shoulder=0.0, elbow=q2, carpal=0.0, fore_fetlock=-(q1 + q2))
    l1, l2, full = HORSE_HIND
    q1, q2 = two_link(x, -(full - HORSE_CROUCH) + lift + HORSE_PASTERN, l1, l2, -1)
    out.update(hip=q1, stifle=q2, tarsal=-q2, hind_fetlock=-q1)
    return {k: math.degrees(v) for k, v in out.items()}


def fourier(values, harmonics):
    """(constant, [(amplitude, k, phase)]) with v(s) = c + sum a sin(2 pi k s + p)."""
    n = len(values)
    terms = []
    for k in range(1, harmonics + 1):
        c = 2 / n * sum(v * math.cos(2 * math.pi * k * i / n) for i, v in enumerate(values))
        s = 2 / n * sum(v * math.sin(2 * math.pi * k * i / n) for i, v in enumerate(values))
        terms.append((round(math.hypot(c, s), 2), k, round(math.atan2(c, s), 3)))
    return round(sum(values) / n, 2), terms


def horse_curves():
    samples = [horse_leg_angles(i / 256) for i in range(256)]
    legs = [(name, *fourier([a[name] for a in samples], HORSE_HARMONICS))
            for name in ("scapula", "shoulder", "elbow", "carpal", "fore_fetlock",
                         "hip", "stifle", "tarsal", "hind_fetlock")]
    # The head and neck nod twice per stride by a few degrees (rounded from
    # the walking horse); the small terms stand for higher harmonics a fit
    # would find, and are dropped like every term under THRESHOLD.
    neck = [
        ("neck_proximal", 0.0, [(3.0, 2, 0.5), (0.6, 1, 0.0)]),
        ("neck_mid", 0.0, [(2.5, 2, 1.0), (0.5, 1, 0.3)]),
        ("atlas", 0.0, [(4.0, 2, 1.5), (0.8, 1, -0.4)]),
    ]
    return legs + neck


HORSE = horse_curves()
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
# Diagonal couplets: each hind foot a tenth of a stride before the opposite
# fore foot, the two diagonals half a stride apart. Support alternates
# between four, three and the two feet of a diagonal, whose line passes
# under the centre of mass; never the two feet of one side, on which the
# lateral-sequence walk (lh 0, lf 0.25, rh 0.5, rf 0.75) rolled this model
# over in every fall traced (docs/evolve.md).
HORSE_LIMBS = [("lh", 0.0), ("lf", 0.6), ("rh", 0.5), ("rf", 0.1), ("neck", 0.0)]
# The same walk for the runtime (configs/gaits/horse_walk.yaml, played by
# configs/robots/horse.yaml) starts a fifth of a stride later. `animrt run`
# ramps from standing to the gait's first pose and then plays the gait at
# full swing, where the evolver's walk blends the swing in over a cycle; the
# start is the fragile part of this walk, and measured in lockstep runs of
# 20 s only this start phase (of 20 tried) walked without a fall, start and
# stop included (docs/evolve.md).
HORSE_RUNTIME_SHIFT = 0.2
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


# ---- the horse as a robot on the runtime -----------------------------------
# configs/robots/horse.yaml: every joint of the model on two simulated
# Dynamixel buses, limits from the model's joint ranges, home in the first
# pose of horse_walk.yaml (all four feet down), so the figure starts standing
# where the walk begins.
HORSE_RANGES = {"scapula": (-70, 40), "shoulder": (-40, 40), "elbow": (-30, 120),
                "carpal": (-90, 10), "fetlock": (-90, 60), "hip": (-60, 60),
                "stifle": (-120, 30), "tarsal": (-30, 120), "neck_proximal": (-30, 30),
                "neck_mid": (-30, 30), "atlas": (-45, 45)}

HORSE_ROBOT_HEADER = """# The horse of configs/models/horse.xml as a robot: 21 joints on two
# simulated Dynamixel Protocol 2.0 buses (fore legs and neck; hind legs),
# playing the horse's seed walk (horse_walk.yaml). Written by
# scripts/experiments/make_grammars.py. Run it on the physics model:
#
#   animrt run configs/robots/horse.yaml --backend sim --physics configs/models/horse.xml
#
# A servo's goal position becomes the target of the model's position
# actuator of the same name (docs/evolve.md, "Playing an evolved gait on
# physics"); the model's actuators, not a Dynamixel's, carry the 540 kg
# figure, so the limits are the model's joint ranges and the speeds a leg of
# this size needs (the walk reaches about 770 deg/s and 18,000 deg/s^2 at
# stifle and tarsus), not an X-series servo's.
# Reference of every key: docs/config.md.

name: horse

loop:
  # 13 and 8 servos: a Sync Write and a Sync Read per bus at 1 Mbaud fit a
  # 5 ms period. At 100 Hz the stiff leg actuators see steps of up to 8
  # degrees every cycle, and lockstep runs fell in 3 of 9 starts.
  rate_hz: 200

safety:
  watchdog_timeout_s: 0.2
  start_ramp_s: 2.0        # home is the walk's first pose: the ramp is short
  # A quick stop plants the feet where they are and brakes the body; over
  # 2 s or 4 s the figure walked on while its legs slowed and tipped over in
  # 5 of 6 lockstep runs (0 of 7 with 0.5 s).
  stop_ramp_s: 0.5

buses:
  fore:
    protocol: dynamixel2
    port: /dev/ttyUSB0
    baud: 1000000
    timeout_ms: 4
    sim:
      wire_time: true
  hind:
    protocol: dynamixel2
    port: /dev/ttyUSB1
    baud: 1000000
    timeout_ms: 4
    sim:
      wire_time: true

# Joint order is the robot's joint order (telemetry columns). Right-side
# servos are mounted mirrored (direction -1).
joints:
"""


def horse_robot_yaml():
    curves = {name: (const, kept(terms)) for name, const, terms in HORSE}
    phase = {l: (p + HORSE_RUNTIME_SHIFT) % 1.0 for l, p in HORSE_LIMBS}

    def first(curve, limb):
        const, terms = curves[curve]
        s = -phase[limb]
        return const + sum(a * math.sin(k * 2 * math.pi * s + p) for a, k, p in terms)

    out = HORSE_ROBOT_HEADER
    ids = {"fore": 0, "hind": 0}
    for joint, curve, limb in HORSE_JOINTS:
        bus = "hind" if limb in ("lh", "rh") else "fore"
        ids[bus] += 1
        kind = joint.split("_", 1)[1] if limb != "neck" else joint
        lo, hi = HORSE_RANGES[kind]
        fast = limb != "neck"
        out += (f"  {joint}:\n"
                f"    limits: {{min_deg: {lo}, max_deg: {hi}, velocity_dps: {1000 if fast else 200}, "
                f"acceleration_dps2: {30000 if fast else 2000}}}\n"
                f"    home_deg: {num(round(first(curve, limb), 2))}\n"
                f"    actuator: {{bus: {bus}, id: {ids[bus]}, ticks_per_rev: 4096, zero_ticks: 2048, "
                f"direction: {-1 if limb in ('rf', 'rh') else 1}}}\n")
    out += ("\nmotion:\n  type: gait\n  file: ../gaits/horse_walk.yaml  # relative to this file's folder\n"
            "\n# The figure's MJCF model, for the dashboard's 3-D view.\nmodel: ../models/horse.xml\n")
    return out


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


def harmonic_rule(k, fraction=0.25):
    """The whole harmonics of the stride within +-fraction of harmonic k.

    The paper varies a term's frequency within 25 % of itself. A frequency
    that is not a whole harmonic makes the curve non-periodic over a stride:
    its phase drifts against the other legs' from cycle to cycle, left and
    right legs (one curve half a stride apart) drift apart, and the looping
    playback jumps at the loop. Every one of 20 seed neighbours with the
    frequencies varied that way fell (docs/evolve.md); whole harmonics keep
    every phenotype a gait that repeats each stride, and harmonic k itself
    is always one of them.
    """
    lo, hi = k * (1 - fraction), k * (1 + fraction)
    return " | ".join(str(h) for h in range(max(1, math.ceil(lo - 1e-9)), math.floor(hi + 1e-9) + 1))


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
            rules += f"<c{i}_f{j}> ::= {harmonic_rule(k)}\n"
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

HORSE_WALK_COMMENT = """# The horse's seed walk (horse_seed.yaml) for the runtime: the same curves
# and limb offsets, started a fifth of a stride later so that the figure
# starting from standing (configs/robots/horse.yaml) gets into the walk.
# Written by scripts/experiments/make_grammars.py."""

HORSE_BALANCE_COMMENT = """# The horse's seed walk (horse_seed.yaml) with the balance reflex: each leg
# on the ground stretches along the trunk's vertical by 0.3 m per unit of sine
# of its side's or end's tilt and 0.1 m per unit per second of its rate (docs/evolve.md,
# "A balance reflex"). Walks in `animrt evolve`, `animrt gait measure`, and
# `animrt run` on a robot with an IMU (imus:) and a model (model:).
# Written by scripts/experiments/make_grammars.py."""

HORSE_BALANCE = "\nbalance: {tilt_m: 0.3, tilt_rate_m_s: 0.1}\n"

QUAD_COMMENT = """# Seed walk of the demo quadruped for gait evolution: the curves of
# configs/gaits/walk.yaml with Froude timing (the fitness targets come from
# the Froude number). Written by scripts/experiments/make_grammars.py."""


def main():
    with open(os.path.join(ROOT, "configs/gaits/horse_seed.yaml"), "w") as f:
        f.write(gait_yaml("horse_seed", HORSE_COMMENT, HORSE, HORSE_FROUDE, HORSE_LIMBS, HORSE_JOINTS))
    with open(os.path.join(ROOT, "configs/gaits/horse_seed_balance.yaml"), "w") as f:
        f.write(gait_yaml("horse_seed_balance", HORSE_BALANCE_COMMENT, HORSE, HORSE_FROUDE,
                          HORSE_LIMBS, HORSE_JOINTS) + HORSE_BALANCE)
    shifted = [(l, round((p + HORSE_RUNTIME_SHIFT) % 1.0, 4)) for l, p in HORSE_LIMBS]
    with open(os.path.join(ROOT, "configs/gaits/horse_walk.yaml"), "w") as f:
        f.write(gait_yaml("horse_walk", HORSE_WALK_COMMENT, HORSE, HORSE_FROUDE, shifted, HORSE_JOINTS))
    with open(os.path.join(ROOT, "configs/robots/horse.yaml"), "w") as f:
        f.write(horse_robot_yaml())
    with open(os.path.join(ROOT, "configs/gaits/quadruped_seed.yaml"), "w") as f:
        f.write(gait_yaml("quadruped_seed", QUAD_COMMENT, QUAD, QUAD_FROUDE, QUAD_LIMBS, QUAD_JOINTS))
    for model, curves in (("horse", HORSE), ("quadruped", QUAD)):
        for style in ("numerical", "concatenating", "hybrid", "sinusoidal", "free"):
            with open(os.path.join(ROOT, f"configs/grammars/{model}_{style}.bnf"), "w") as f:
                f.write(grammar(model, style, curves))


if __name__ == "__main__":
    main()
