#!/usr/bin/python3
"""The sequence network on the longest real game clips that Debian ships.

    /usr/bin/python3 scripts/experiments/seq_real_clips.py build/bin/animrt OUT survey
    /usr/bin/python3 scripts/experiments/seq_real_clips.py build/bin/animrt OUT run ITERATIONS \
        [--window W] [--training-clip] [MODEL:PART ...]

(from the repository root). `survey` extracts every player model's
lower.md3 / upper.md3 and animation.cfg from OpenArena's .pk3 files
(openarena-data and the packages it depends on) and Irrlicht's MD2 files
(libirrlicht-doc), reads each through `animrt seq features` (the project's
own readers, so a reader error on a real file shows here) and writes
OUT/clips.tsv: file, clip, frames, vertices.

`run` takes the given files (default: the ones in GROUPS below), and for
each one:

- holds out its longest clip whole (`--held-out-clip`) and trains a model
  at the default network settings on its other clips, with the window cut
  to the longest training clip (at most the default 32) and ITERATIONS
  iterations, one thread, seed 1; the CPU seconds of the training are
  measured. `--window W` sets the window instead (a tuned variant, labelled
  so in the results); `--training-clip` also completes the longest clip it
  was trained on, as a check of what it learned;
- trains a reference of one iteration at a learning rate of 1e-12: the
  untrained network, whose output layer starts at zero, so it completes as
  linear interpolation of the keys' features and placement;
- on the held-out clip, for gaps of 1, 3, 5 and 9 frames: keys every gap + 1
  frames from the clip's first frame (true frames, `seq reconstruct` of the
  feature file: absolute coordinates), completed by `animrt seq complete`
  (defaults: threshold 0.05, 20 retries), and compared with linear vertex
  interpolation of the same keys and with holding the earlier key. The error
  of a frame is the mean vertex distance from the true frame over the true
  frame's bounding-box diagonal; the figure is the mean over every
  in-between frame, in per cent. Nothing is aligned.

Printed: one line per file and gap; OUT/results.tsv holds the same, and
`table` prints it as the Markdown table of docs/results/seqnet_real_clips.md:

    /usr/bin/python3 scripts/experiments/seq_real_clips.py build/bin/animrt OUT table
"""
import glob
import math
import os
import resource
import shutil
import struct
import subprocess
import sys
import time

PAKS = '/usr/share/games/openarena/baseoa'
IRRLICHT = '/usr/share/doc/libirrlicht-dev/media'
GAPS = (1, 3, 5, 9)
DEFAULT_WINDOW = 32
# The files `run` takes by default: the ones whose longest clips are the
# longest of the survey (docs/results/seqnet_real_clips.md).
GROUPS = ['sarge:upper', 'sorceress:lower', 'irrlicht:sydney', 'irrlicht:faerie']


def extract(out):
    """Every player's lower/upper.md3 and animation.cfg, later .pk3 files
    overriding earlier ones as the engine loads them; Irrlicht's MD2s."""
    models = os.path.join(out, 'models')
    os.makedirs(models, exist_ok=True)
    for pak in sorted(glob.glob(os.path.join(PAKS, '*.pk3'))):
        names = subprocess.run(['unzip', '-Z1', pak], capture_output=True, text=True,
                               check=True).stdout.split()
        for name in names:
            parts = name.split('/')
            if (len(parts) == 4 and parts[:2] == ['models', 'players']
                    and parts[3] in ('lower.md3', 'upper.md3', 'animation.cfg')):
                folder = os.path.join(models, parts[2])
                os.makedirs(folder, exist_ok=True)
                with open(os.path.join(folder, parts[3]), 'wb') as f:
                    f.write(subprocess.run(['unzip', '-p', pak, name], capture_output=True,
                                           check=True).stdout)
    for path in sorted(glob.glob(os.path.join(IRRLICHT, '*.md2.gz'))):
        folder = os.path.join(models, 'irrlicht')
        os.makedirs(folder, exist_ok=True)
        shutil.copy(path, folder)


def files(out):
    models = os.path.join(out, 'models')
    found = sorted(glob.glob(os.path.join(models, '*', '*.md3')))
    return found + sorted(glob.glob(os.path.join(models, 'irrlicht', '*.md2.gz')))


def label(path):
    return os.path.basename(os.path.dirname(path)) + ':' + os.path.basename(path).split('.')[0]


def read_clips(path):
    """Clips and vertex count of a feature file (docs/seqnet.md, version 2)."""
    with open(path, 'rb') as f:
        data = f.read()
    _, vertices, triangles, frames, clips, _, _ = struct.unpack_from('<7I', data, 8)
    at = 36 + 24 * vertices + 12 * triangles
    out = []
    for _ in range(clips):
        (n,) = struct.unpack_from('<I', data, at)
        name = data[at + 4:at + 4 + n].decode()
        first, count, fps = struct.unpack_from('<iid', data, at + 4 + n)
        out.append((name, first, count, fps))
        at += 4 + n + 16
    return vertices, frames, out


def features(animrt, src, dst):
    os.makedirs(os.path.dirname(dst), exist_ok=True)
    r = subprocess.run([animrt, 'seq', 'features', src, '--out', dst], capture_output=True,
                       text=True)
    return r.returncode, (r.stderr or r.stdout).strip()


def survey(animrt, out):
    extract(out)
    rows, errors = [], []
    for path in files(out):
        bin_path = os.path.join(out, 'features', label(path).replace(':', '_') + '.bin')
        code, message = features(animrt, path, bin_path)
        if code != 0:
            errors.append(f'{label(path)}: exit {code}: {message}')
            continue
        vertices, frames, clips = read_clips(bin_path)
        for name, first, count, fps in clips:
            rows.append((label(path), name, count, vertices, frames, fps))
    with open(os.path.join(out, 'clips.tsv'), 'w') as f:
        f.write('file\tclip\tframes\tvertices\tfile_frames\tfps\n')
        for r in rows:
            f.write('\t'.join(str(x) for x in r) + '\n')
    for e in errors:
        print('reader error:', e)
    rows.sort(key=lambda r: -r[2])
    print('longest clips:')
    for r in rows[:40]:
        print('  %-22s %-16s %3d frames %5d vertices %g fps' % (r[0], r[1], r[2], r[3], r[5]))


def read_obj(path):
    v = []
    with open(path) as f:
        for line in f:
            if line.startswith('v '):
                v.append(tuple(float(x) for x in line.split()[1:4]))
    return v


def pieces_of(path):
    """Connected pieces of an OBJ's triangles, as lists of vertex indices."""
    parent = list(range(len(read_obj(path))))

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    with open(path) as f:
        for line in f:
            if line.startswith('f '):
                idx = [int(x.split('/')[0]) - 1 for x in line.split()[1:]]
                for j in idx[1:]:
                    parent[root(j)] = root(idx[0])
    groups = {}
    for i in range(len(parent)):
        groups.setdefault(root(i), []).append(i)
    return list(groups.values())


def aligned(a, truth, pieces):
    """a with each piece moved by its mean offset from the truth: the shape
    alone, without where the pieces are."""
    out = list(a)
    for piece in pieces:
        d = [sum(truth[i][c] - a[i][c] for i in piece) / len(piece) for c in range(3)]
        for i in piece:
            out[i] = tuple(a[i][c] + d[c] for c in range(3))
    return out


def diagonal(v):
    return math.sqrt(sum((max(p[i] for p in v) - min(p[i] for p in v)) ** 2 for i in range(3)))


def error(a, truth):
    return sum(math.dist(p, q) for p, q in zip(a, truth)) / len(truth) / diagonal(truth)


def cpu_of_children():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def train(animrt, bin_path, model, held, window, iterations, extra=()):
    before, start = cpu_of_children(), time.time()
    r = subprocess.run([animrt, 'seq', 'train', bin_path, '--out', model, '--iterations',
                        str(iterations), '--threads', '1', '--seed', '1', '--window', str(window),
                        '--held-out-clip', held, '--held-out-every', '0', '--report-every', '50',
                        '--checkpoint-every', str(iterations)] + list(extra),
                       capture_output=True, text=True, check=True)
    lines = [l for l in r.stdout.splitlines() if l.startswith('held out at')]
    return cpu_of_children() - before, time.time() - start, lines[-1] if lines else ''


def complete(animrt, model, keys, gap, done):
    shutil.rmtree(done, ignore_errors=True)
    r = subprocess.run([animrt, 'seq', 'complete', model, '--keys'] + keys
                       + ['--gap', str(gap), '--out', done], capture_output=True, text=True,
                       check=True)
    frames = sorted(glob.glob(os.path.join(done, 'frame_*.obj')))
    return [read_obj(p) for p in frames], r.stdout.count(': merged at')


def evaluate(animrt, work, truth_dir, clip, model, untrained):
    """Completion of `clip` (name, first, count) for every gap of GAPS: one
    dict of errors (per cent of the diagonal) per gap."""
    truth = [os.path.join(truth_dir, 'frame_%04d.obj' % (clip[1] + k)) for k in range(clip[2])]
    pieces = pieces_of(truth[0])
    frames = [read_obj(p) for p in truth]
    motion = 100 * sum(error(frames[k - 1], frames[k]) for k in range(1, len(frames))) / (
        len(frames) - 1)
    print(f'  {clip[0]}: {len(pieces)} pieces; mean motion between frames {motion:.2f} % of the '
          'diagonal')
    out = []
    for gap in GAPS:
        n = (clip[2] - 1) // (gap + 1) * (gap + 1) + 1
        if n < gap + 2:
            continue
        key_paths = truth[0:n:gap + 1]
        net, merged = complete(animrt, model, key_paths, gap, os.path.join(work, 'done'))
        plain, _ = complete(animrt, untrained, key_paths, gap, os.path.join(work, 'plain'))
        sums = dict.fromkeys(('net', 'untrained', 'linear', 'hold', 'net_shape', 'linear_shape'),
                             0.0)
        count = 0
        for g in range(len(key_paths) - 1):
            a, b = frames[g * (gap + 1)], frames[(g + 1) * (gap + 1)]
            for t in range(1, gap + 1):
                k = g * (gap + 1) + t
                s = t / (gap + 1)
                lin = [tuple((1 - s) * p[i] + s * q[i] for i in range(3)) for p, q in zip(a, b)]
                sums['net'] += error(net[k], frames[k])
                sums['untrained'] += error(plain[k], frames[k])
                sums['linear'] += error(lin, frames[k])
                sums['hold'] += error(a, frames[k])
                sums['net_shape'] += error(aligned(net[k], frames[k], pieces), frames[k])
                sums['linear_shape'] += error(aligned(lin, frames[k], pieces), frames[k])
                count += 1
        e = {k: 100 * v / count for k, v in sums.items()}
        e.update(gap=gap, gaps=len(key_paths) - 1, merged=merged, motion=motion)
        print(f'  gap {gap}: {e["gaps"]} gaps ({merged} merged), network {e["net"]:.2f} %, '
              f'untrained {e["untrained"]:.2f} %, linear vertex interpolation '
              f'{e["linear"]:.2f} %, hold {e["hold"]:.2f} %; pieces aligned: network '
              f'{e["net_shape"]:.2f} %, linear {e["linear_shape"]:.2f} %')
        out.append(e)
    return out


def run(animrt, out, iterations, chosen, fixed_window=None, training_clip=False):
    if not os.path.isdir(os.path.join(out, 'models')):
        extract(out)
    results = os.path.join(out, 'results.tsv')
    with open(results, 'a') as log:
        for name in chosen:
            src = [p for p in files(out) if label(p) == name][0]
            tag = name.replace(':', '_')
            bin_path = os.path.join(out, 'features', tag + '.bin')
            if not os.path.exists(bin_path):
                features(animrt, src, bin_path)
            vertices, _, clips = read_clips(bin_path)
            held = max(clips, key=lambda c: c[2])
            others = [c[2] for c in clips if c is not held]
            window = fixed_window or min(DEFAULT_WINDOW, max(others))
            windows = sum(max(0, c - window + 1) for c in others)
            work = os.path.join(out, 'run', f'{tag}_w{window}_i{iterations}')
            truth_dir = os.path.join(out, 'truth', tag)
            if not os.path.isdir(truth_dir):
                subprocess.run([animrt, 'seq', 'reconstruct', bin_path, '--out', truth_dir],
                               check=True, capture_output=True)
            os.makedirs(work, exist_ok=True)
            model = os.path.join(work, 'net.model')
            cpu, wall, line = train(animrt, bin_path, model, held[0], window, iterations)
            print(f'{name}: held out {held[0]} ({held[2]} frames, {vertices} vertices), window '
                  f'{window} ({windows} training windows in {sum(others)} frames of '
                  f'{len(others)} clips), {iterations} iterations in {cpu:.0f} CPU s '
                  f'({wall:.0f} s wall)')
            print(f'  trainer: {line}')
            untrained = os.path.join(work, 'untrained.model')
            train(animrt, bin_path, untrained, held[0], window, 1, ['--learning-rate', '1e-12'])
            evaluated = [(held, held[0])]
            if training_clip:
                trained_on = max((c for c in clips if c is not held), key=lambda c: c[2])
                evaluated.append((trained_on, trained_on[0] + ' (trained on)'))
            for clip, clip_label in evaluated:
                for e in evaluate(animrt, work, truth_dir, clip, model, untrained):
                    row = ('window %d' % window if fixed_window else 'default', name, clip_label,
                           clip[2], vertices, window, windows, e['gap'], e['gaps'], e['merged'],
                           iterations, round(cpu)) + tuple(
                               '%.2f' % e[k] for k in ('net', 'untrained', 'linear', 'hold',
                                                       'net_shape', 'linear_shape', 'motion'))
                    log.write('\t'.join(str(x) for x in row) + '\n')
                    log.flush()


def table(out):
    print('| setting | file | held-out clip | frames | vertices | window (training windows) | '
          'iterations (CPU s) | gap | gaps | network | untrained network | linear vertex '
          'interpolation | hold earlier key | network, pieces aligned | linear, pieces aligned |')
    print('|' + '---|' * 15)
    with open(os.path.join(out, 'results.tsv')) as f:
        rows = [line.rstrip('\n').split('\t') for line in f]
    # By file, the default setting first, then by iterations, clip and gap.
    rows.sort(key=lambda r: (r[1], r[0] != 'default', r[0], int(r[10]), r[2], int(r[7])))
    for row in rows:
        (setting, name, clip, frames, vertices, window, windows, gap, gaps, merged, iterations,
         cpu, net, untrained, linear, hold, net_shape, linear_shape, _) = row
        mark = '**' if float(net) < min(float(linear), float(hold)) else ''
        print(f'| {setting} | {name} | {clip} | {frames} | {vertices} | {window} ({windows}) | '
              f'{iterations} ({cpu}) | {gap} | {gaps} | {mark}{net}{mark} | {untrained} | '
              f'{linear} | {hold} | {net_shape} | {linear_shape} |')


def main():
    animrt, out, what = sys.argv[1], sys.argv[2], sys.argv[3]
    if what == 'survey':
        survey(animrt, out)
    elif what == 'table':
        table(out)
    else:
        iterations, rest, window, training_clip = int(sys.argv[4]), sys.argv[5:], None, False
        while rest[:1] in (['--window'], ['--training-clip']):
            if rest[0] == '--window':
                window, rest = int(rest[1]), rest[2:]
            else:
                training_clip, rest = True, rest[1:]
        run(animrt, out, iterations, rest or GROUPS, window, training_clip)


if __name__ == '__main__':
    main()
