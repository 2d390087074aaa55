"""The falls summary of scripts/experiments/summarise.py (falls.md) against
an example worked by hand."""
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts", "experiments"))
import summarise  # noqa: E402


def run(fell_by_generation, speed, stride, duty):
    """One run's CSV rows as csv.DictReader gives them: the last row carries
    the best gait's measures."""
    return [{"generation": str(g), "fell": str(f), "best_speed": str(speed),
             "best_stride_length": str(stride), "best_duty_factor": str(duty)}
            for g, f in enumerate(fell_by_generation)]


class FallsRow(unittest.TestCase):
    def test_falls_from_generation_ten_and_best_gaits_against_the_targets(self):
        # Population 4. Generations 0-9 do not count. Run a falls 1 and 2 in
        # generations 10 and 11 (25 %, 50 %), run b 0 and 4 (0 %, 100 %): per
        # generation over runs 12.5 % and 75 %, mean 43.75 %, the worst
        # generation's mean 75 %, the worst of a single run 100 %. Run a's
        # best gait is on every target; run b's duty factor 0.5 is 25 % under
        # 0.67, so 1 of 2 is within 15 %.
        a = run([4] * 10 + [1, 2], 1.534, 1.991, 0.67)
        b = run([0] * 10 + [0, 4], 1.434, 1.891, 0.5)
        row = summarise.falls_row("hybrid", [a, b], 4)
        cells = [c.strip() for c in row.strip("|").split("|")]
        self.assertEqual(cells[0], "Numerical & concatenating functions")
        self.assertEqual(cells[1:5], ["2", "43.8", "75.0", "100.0"])
        self.assertEqual(cells[5], "1.484 / 1.941 / 0.585")
        self.assertEqual(cells[6], "1 of 2")

    def test_a_run_that_ended_before_generation_ten_gives_no_row(self):
        self.assertIsNone(summarise.falls_row("free", [run([1] * 5, 1, 1, 1)], 4))


if __name__ == "__main__":
    unittest.main()
