#!/usr/bin/python3
"""Joint-space completion of 9-frame gaps on the quadruped's gait data.

    /usr/bin/python3 scripts/experiments/seq_joint_completion.py build/bin/animrt OUT [ITERATIONS]

(from the repository root). Writes into OUT: a training corpus (the
quadruped's two gaits at 3 Froude numbers and 3 seeds: 18 sequences of 160
frames) and an unseen test corpus (the same with seed 10 only: 6
sequences), trains a joint model on the training
CSVs (`animrt seq train`, default 600 iterations, one thread), then cuts
every test sequence into keys every 10 frames and completes the 9 frames
between them with `animrt seq complete`. Printed: the mean absolute joint
angle error (rad) over all in-between frames of the learned completion, of
linear interpolation and of Catmull-Rom cubic interpolation of the same keys
(end keys repeated), and how many gaps merged below the threshold.
"""
import csv
import glob
import os
import subprocess
import sys

GAP = 9


def read(path):
    rows = list(csv.reader(open(path)))
    cols = [i for i, n in enumerate(rows[0]) if n != 'time_s' and not n.startswith('torso_')]
    return [rows[0][i] for i in cols], [[float(r[i]) for i in cols] for r in rows[1:]]


def main():
    animrt, out = sys.argv[1], sys.argv[2]
    iterations = sys.argv[3] if len(sys.argv) > 3 else '600'
    os.makedirs(out, exist_ok=True)
    for name, seed in (('train', ['--seed', '1', '--seeds', '3']), ('test', ['--seed', '10', '--seeds', '1'])):
        subprocess.run([animrt, 'seq', 'corpus', '--out', os.path.join(out, name), '--frames', '160',
                        '--vertices', '100', '--quiet'] + seed, check=True)
    model = os.path.join(out, 'joints.model')
    subprocess.run([animrt, 'seq', 'train', '--out', model, '--iterations', iterations,
                    '--report-every', '100', '--threads', '1', '--seed', '3']
                   + sorted(glob.glob(os.path.join(out, 'train', '*_seed*.csv'))), check=True)
    total = {'learned': [0.0, 0], 'linear': [0.0, 0], 'cubic': [0.0, 0]}
    merged = gaps = 0
    keys_csv, done_csv = os.path.join(out, 'keys.csv'), os.path.join(out, 'done.csv')
    for path in sorted(glob.glob(os.path.join(out, 'test', '*_seed*.csv'))):
        names, frames = read(path)
        n = (len(frames) - 1) // (GAP + 1) * (GAP + 1) + 1
        keys = frames[0:n:GAP + 1]
        with open(keys_csv, 'w') as f:
            f.write(','.join(names) + '\n')
            for k in keys:
                f.write(','.join(repr(v) for v in k) + '\n')
        report = subprocess.run([animrt, 'seq', 'complete', model, '--keys', keys_csv, '--gap', str(GAP),
                                 '--out', done_csv], capture_output=True, text=True, check=True).stdout
        merged += report.count(': merged at')
        gaps += report.count('gap ')
        _, done = read(done_csv)
        joints = len(names)
        for g in range(len(keys) - 1):
            a, b = keys[g], keys[g + 1]
            pa = keys[g - 1] if g > 0 else a
            pb = keys[g + 2] if g + 2 < len(keys) else b
            for t in range(1, GAP + 1):
                s = t / (GAP + 1)
                truth = frames[g * (GAP + 1) + t]
                linear = [(1 - s) * a[j] + s * b[j] for j in range(joints)]
                cubic = [0.5 * (2 * a[j] + (b[j] - pa[j]) * s + (2 * pa[j] - 5 * a[j] + 4 * b[j] - pb[j]) * s * s
                                + (3 * a[j] - pa[j] - 3 * b[j] + pb[j]) * s ** 3) for j in range(joints)]
                learned = done[g * (GAP + 1) + t]
                for name, v in (('learned', learned), ('linear', linear), ('cubic', cubic)):
                    total[name][0] += sum(abs(v[j] - truth[j]) for j in range(joints))
                    total[name][1] += joints
    for name, (s, c) in total.items():
        print(f'{name}: mean absolute error {s / c:.4f} rad')
    print(f'merged below the threshold: {merged} of {gaps} gaps')


if __name__ == '__main__':
    main()
