"""The falls summary of scripts/experiments/summarise.py (falls.md) and the
structured-mapping rank test (ranks.md) against examples worked by hand."""
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


class RankClaims(unittest.TestCase):
    def rows(self, text):
        return [[c.strip() for c in line.strip("|").split("|")]
                for line in text.strip().splitlines()[2:]]

    def test_structured_mapping_against_the_hybrid_on_each_runs_falls(self):
        # Every structured run falls less than every standard one: U = 0, and
        # of the C(8, 4) = 70 ways to rank 4 + 4 runs only this one gives it,
        # p = 1/70 = 0.0143.
        falls = {"hybrid": [0.5, 0.4, 0.3, 0.45], "hybrid_structured": [0.1, 0.2, 0.05, 0.15]}
        rows = self.rows(summarise.rank_claims({}, falls))
        self.assertEqual(len(rows), 1)
        self.assertEqual(rows[0][0], "structured mapping: fewer falls from gen 10 than")
        self.assertEqual(rows[0][2:4], ["0.0", "0.0143"])
        self.assertEqual(rows[0][5], "yes")
        # Swapped, the claim does not hold: U = 16, p = 1.
        swapped = {"hybrid": falls["hybrid_structured"], "hybrid_structured": falls["hybrid"]}
        rows = self.rows(summarise.rank_claims({}, swapped))
        self.assertEqual(rows[0][2:4], ["16.0", "1.0000"])
        self.assertEqual(rows[0][5], "no")

    def test_the_papers_claims_compare_only_the_papers_configurations(self):
        finals = {"hybrid": [90, 91], "free": [100, 120], "hybrid_structured": [80, 81]}
        rows = self.rows(summarise.rank_claims(finals))
        against = [r[1] for r in rows]
        self.assertEqual(against, ["free", "hybrid", "hybrid"])  # best; worst; most variable
        self.assertNotIn("hybrid_structured", against)


if __name__ == "__main__":
    unittest.main()
