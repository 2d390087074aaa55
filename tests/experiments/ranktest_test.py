"""The rank test of scripts/experiments/ranktest.py against examples worked
by hand."""
import math
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts", "experiments"))
import ranktest  # noqa: E402


class RankTest(unittest.TestCase):
    def test_ranks_share_ties(self):
        self.assertEqual(ranktest.ranks([10, 20, 20, 5, 20]), [2, 4, 4, 1, 4])

    def test_separated_samples(self):
        # a below b entirely: U_a = 0; one arrangement of C(6,3) = 20.
        r = ranktest.mann_whitney_u([1, 2, 3], [4, 5, 6])
        self.assertEqual((r["u_a"], r["u_b"], r["method"]), (0, 9, "exact"))
        self.assertAlmostEqual(r["p_less"], 1 / 20)
        self.assertAlmostEqual(r["p_two_sided"], 2 / 20)
        r = ranktest.mann_whitney_u([4, 5, 6], [1, 2, 3])
        self.assertEqual(r["u_a"], 9)
        self.assertAlmostEqual(r["p_less"], 1.0)

    def test_interleaved_samples(self):
        # a = 1,3,5 has ranks 1,3,5: R = 9, U_a = 9 - 6 = 3. The counts of
        # U = 0..9 for n = m = 3 are 1,1,2,3,3,3,3,2,1,1: P(U <= 3) = 7/20.
        self.assertEqual(ranktest.u_distribution(3, 3), [1, 1, 2, 3, 3, 3, 3, 2, 1, 1])
        r = ranktest.mann_whitney_u([1, 3, 5], [2, 4, 6])
        self.assertEqual(r["u_a"], 3)
        self.assertAlmostEqual(r["p_less"], 7 / 20)
        self.assertAlmostEqual(r["p_two_sided"], 14 / 20)

    def test_ties_use_the_corrected_normal_approximation(self):
        # Pooled 1 2 2 2 3 3 3 4: ranks 1, 3 3 3, 6 6 6, 8. a = 1,2,2,3 ranks
        # 1+3+3+6 = 13, U_a = 13 - 10 = 3; mean 8; ties of 3 and 3:
        # var = 16/12 (9 - 48/56) = 76/7; z = (3 - 8 + 0.5)/sqrt(76/7) = -1.3657,
        # Phi(-1.3657) = 0.0860 from the table.
        r = ranktest.mann_whitney_u([1, 2, 2, 3], [2, 3, 3, 4])
        self.assertEqual(r["method"], "normal")
        self.assertEqual(r["u_a"], 3)
        self.assertAlmostEqual(r["variance"], 76 / 7)
        self.assertAlmostEqual(r["p_less"], 0.0860, places=3)
        self.assertAlmostEqual(r["p_two_sided"], 0.1720, places=3)

    def test_exact_and_normal_agree_on_larger_samples(self):
        a = [0.5 * i for i in range(12)]
        b = [0.5 * i + 1.75 for i in range(12)]
        exact = ranktest.mann_whitney_u(a, b)
        self.assertEqual(exact["method"], "exact")
        # The same samples with one tie forced in take the normal path.
        tied = ranktest.mann_whitney_u(a + [100.0], b + [100.0])
        self.assertEqual(tied["method"], "normal")
        self.assertLess(abs(exact["p_less"] - tied["p_less"]), 0.02)

    def test_spread(self):
        wide = [1, 10, 20, 30, 40, 50]
        narrow = [24, 25, 25.5, 26, 27, 28]
        self.assertLess(ranktest.spread_test(wide, narrow)["p_less"], 0.05)
        self.assertGreater(ranktest.spread_test(narrow, wide)["p_less"], 0.5)

    def test_empty_sample_is_refused(self):
        with self.assertRaises(ValueError):
            ranktest.mann_whitney_u([], [1.0])


if __name__ == "__main__":
    unittest.main()
