"""The layers' dependency rules (docs/architecture.md), checked on the tree.

Usage: layering.py SOURCE_DIR BUILD_DIR

Every #include of one of our headers (animrt/<layer>/...) must point the
way the layers do: core includes nothing of ours; firmware_bridge only core;
the motion that plays (controllers/, outside learn/) no bridge, sim, runtime
or learner; the learners (controllers/learn/) no bridge or runtime, and sim
only from the corpus generator that walks figures on MuJoCo; sim no learner;
the runtime library no sim, no learner and no herd (Recast); the loop
(runtime/src and runtime/config, but the figure builder) neither the
dashboards nor the builder above it, nor an HTTP server. Then what the
runtime library links, as CMake wrote it at configure time: no learner, no
libtorch, no MPI, no simulator, no Recast, no MuJoCo; and what the loop's
library (animrt_loop) links: none of those, no dashboard, no HTTP server.
Prints one line per violation and exits 1 if there is any.
"""

import pathlib
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s*[<"](animrt/([a-z_]+)/[^">]*)[">]')
HTTP_INCLUDE = re.compile(r'^\s*#\s*include\s*[<"](httplib\.h)[">]')

# The runtime's files above the loop: the figure builder (which serves a
# dashboard beside a run) and the dashboards' servers.
RUNTIME_ABOVE_LOOP = ("runtime/src/figure.cpp", "runtime/include/animrt/runtime/figure.hpp",
                      "runtime/dashboard/")

# Files the runtime's folder holds that do not build into animrt_runtime:
# the dashboards of a herd and of an evolve run are targets of their own
# (animrt_herd_dashboard, animrt_evolve_dashboard) that the CLI links.
RUNTIME_FRONT_ENDS = {
    "runtime/dashboard/src/herd_dashboard.cpp",
    "runtime/dashboard/include/animrt/runtime/herd_dashboard.hpp",
    "runtime/dashboard/src/evolve_dashboard.cpp",
    "runtime/dashboard/include/animrt/runtime/evolve_dashboard.hpp",
}


def layer_of(rel):
    """The rule set a file falls under, or None for folders without rules."""
    if rel.startswith("core/"):
        return "core"
    if rel.startswith("firmware_bridge/"):
        return "bridge"
    if rel.startswith("controllers/learn/seq_corpus/") or rel.startswith(
            "controllers/learn/include/animrt/learn/seq_corpus/"):
        return "learn_physics"
    if rel.startswith(("controllers/learn/evolve/",
                       "controllers/learn/include/animrt/learn/evolve/")):
        return "learn_evolve"  # animrt_evolve, linked alone by the fuzz harnesses
    if rel.startswith("controllers/learn/"):
        return "learn"
    if rel.startswith("controllers/"):
        return "play"
    if rel.startswith("sim/"):
        return "sim"
    if rel.startswith("runtime/cli/"):
        return None  # the executables link whatever they run
    if rel.startswith("runtime/herd/"):
        return "runtime_herd"  # animrt_runtime_herd: a figure steered by a herd
    if rel in RUNTIME_FRONT_ENDS:
        return "runtime_front_end"
    if rel.startswith(RUNTIME_ABOVE_LOOP):
        return "runtime"
    if rel.startswith("runtime/"):
        return "loop"
    return None


# Per rule set: the header folders (animrt/<folder>/) it may include, and the
# header paths allowed beyond them.
ALLOWED = {
    "core": ({"core"}, set()),
    "bridge": ({"core", "bridge"}, set()),
    "play": ({"core", "controllers"}, set()),
    "learn": ({"core", "controllers", "learn"}, set()),
    "learn_evolve": ({"core", "controllers", "learn"}, set()),
    "learn_physics": ({"core", "controllers", "learn", "sim"}, set()),
    # sim implements two interfaces the runtime declares: posing a figure
    # (sim/mujoco) and standing behind a figure as its backend (the builder
    # runs a figure on it). Headers only; the runtime never includes sim.
    "sim": ({"core", "bridge", "sim", "controllers"},
            {"animrt/runtime/figure_kinematics.hpp", "animrt/runtime/figure_backend.hpp"}),
    "loop": ({"core", "bridge", "controllers", "runtime"}, set()),
    "runtime": ({"core", "bridge", "controllers", "runtime"}, set()),
    "runtime_front_end": ({"core", "bridge", "controllers", "runtime", "learn"}, set()),
    "runtime_herd": ({"core", "bridge", "controllers", "runtime"}, set()),
}

# Header paths a rule set may not include even inside an allowed folder.
FORBIDDEN_PREFIXES = {
    # The evolver links no other learner (its fuzz harnesses link it alone).
    "learn_evolve": ("animrt/learn/head", "animrt/learn/seqnet/", "animrt/learn/seq_corpus/"),
    "runtime": ("animrt/controllers/herd/",),  # Recast: animrt_herd, not the loop's
    # The loop knows no dashboard and no builder: they sit above it.
    "loop": ("animrt/controllers/herd/", "animrt/runtime/dashboard.hpp",
             "animrt/runtime/herd_dashboard.hpp", "animrt/runtime/evolve_dashboard.hpp",
             "animrt/runtime/figure.hpp"),
}


def include_violations(root):
    out = []
    for path in sorted(root.rglob("*")):
        if path.suffix not in (".cpp", ".hpp", ".h") or not path.is_file():
            continue
        rel = path.relative_to(root).as_posix()
        if rel.startswith(("build", "tests/", "bench/")):
            continue
        layer = layer_of(rel)
        if layer is None:
            continue
        folders, extra = ALLOWED[layer]
        banned = FORBIDDEN_PREFIXES.get(layer, ())
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            if layer == "loop" and HTTP_INCLUDE.match(line):
                out.append(f"{rel}:{number}: a loop file includes httplib.h")
                continue
            match = INCLUDE.match(line)
            if not match:
                continue
            header, folder = match.group(1), match.group(2)
            if (folder in folders or header in extra) and not header.startswith(banned):
                continue
            out.append(f"{rel}:{number}: a {layer} file includes {header}")
    return out


# Anything in the runtime library's link closure whose name matches is a
# learner or a dependency the loop must not carry.
FORBIDDEN_LINKS = re.compile(
    r"animrt_(learn|evolve|seq_corpus|evolve_mpi|seqnet_torch|sim|herd|evolve_dashboard|"
    r"herd_dashboard)\b|torch|c10|MPI|mpi|Recast|Detour|mujoco", re.IGNORECASE)


# What the loop's library must not link beyond that: the dashboards, the
# builder that serves them, an HTTP server.
LOOP_FORBIDDEN_LINKS = re.compile(
    r"animrt_(runtime|dashboard)\b|httplib", re.IGNORECASE)


def link_violations(build, target, forbidden):
    closure = build / "link_closure" / f"{target}.txt"
    if not closure.is_file():
        return [f"{closure}: missing (CMake writes it at configure time)"]
    out = []
    for line in closure.read_text().splitlines():
        kind, _, rest = line.partition(" ")
        if kind == "source":
            owner, _, source = rest.partition(" ")
            if source.startswith("controllers/learn/") or source.startswith("sim/"):
                out.append(f"{target} links {owner}, which compiles {source}")
            elif target == "animrt_loop" and source.startswith(RUNTIME_ABOVE_LOOP):
                out.append(f"{target} links {owner}, which compiles {source}")
        elif any(f.search(rest) for f in forbidden):
            out.append(f"{target} links {rest}")
    return out


def main():
    root, build = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    problems = (include_violations(root) +
                link_violations(build, "animrt_runtime", [FORBIDDEN_LINKS]) +
                link_violations(build, "animrt_loop", [FORBIDDEN_LINKS, LOOP_FORBIDDEN_LINKS]))
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} layering violation(s)")
        return 1
    print("layering: every include and the runtime's and the loop's link closures "
          "follow the rules")
    return 0


if __name__ == "__main__":
    sys.exit(main())
