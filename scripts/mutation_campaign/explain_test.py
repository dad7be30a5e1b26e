#!/usr/bin/python3
"""Tests of the mutation campaign's judge (explain.py): each rule explains the mutants it states and no
other. The cases are the campaign's last unexplained exit-0 mutants of issue 36 (seed 36) in small."""
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import explain  # noqa: E402
import kinds  # noqa: E402

KINDS = {k.name: k for k in kinds.all_kinds()}
OPS = [{"op": "value", "desc": "value"}]


def judge(kind, seed, mutant):
    return explain.explain(KINDS[kind], {"repo": "", "seed_name": "seed"}, seed.encode(), mutant.encode(), OPS)


def tracker_row(smr_x, joints):
    """A row of N1N2N3Jval.csv: three SMRs (mm), six unused zeros, six joint readings (deg)."""
    smrs = [smr_x, -1596.4, 605.6, smr_x - 85.6, -1711.7, 802.9, smr_x - 181.6, -1687.1, 468.2]
    return " ".join("%.18e" % v for v in smrs + [0.0] * 6 + joints)


class TrackerRows(unittest.TestCase):
    SEED = "\n".join(tracker_row(x, [j, 0, 0, 0, 0, 0]) for x, j in ((-766.3, 51), (702.6, -9), (555.7, 3))) + "\n"

    def mutant(self, j3):
        rows = [tracker_row(702.6, [-9, 0, 0, 0, 0, 0]), tracker_row(555.7, [3, 0, j3, 0, 0, 0])]
        return "\n".join(rows) + "\n"

    def test_a_row_deleted_and_a_reading_changed_within_the_range_is_valid(self):
        # seed 36's #2393: line 6 deleted, a J3 reading 0 -> 1e-7 deg (two rules at once)
        valid, why = judge("tracker", self.SEED, self.mutant(1e-7))
        self.assertTrue(valid, why)
        self.assertIn("records of `rows` removed", why)
        self.assertIn("a joint reading inside the reader's range [-720, 720] deg", why)

    def test_a_reading_outside_the_range_is_not(self):
        valid, why = judge("tracker", self.SEED, self.mutant(1000.0))
        self.assertFalse(valid, why)

    def test_a_row_of_other_measurements_is_not_an_edited_row(self):
        rows = [tracker_row(702.6, [-9, 0, 0, 0, 0, 0]), tracker_row(5.5e6, [3, 0, 0, 0, 0, 0])]
        valid, why = judge("tracker", self.SEED, "\n".join(rows) + "\n")
        self.assertFalse(valid, why)

    def test_rows_only_removed_stay_valid(self):
        valid, why = judge("tracker", self.SEED, "\n".join(self.SEED.splitlines()[1:]) + "\n")
        self.assertTrue(valid, why)


class CalibratedModelParameters(unittest.TestCase):
    SEED = "format: selfcal-calibrated-model\nparameters:\n  j2.theta_deg: 0.1952568208298091\n  j2.a_mm: 0.5\n"

    def test_an_angle_of_the_identified_vector_within_the_readers_range_is_valid(self):
        # seed 36's #67: j2.theta_deg 0.195 -> 195.26 deg (x1000): a rotation, as -164.74 deg is
        valid, why = judge("calibrated_model", self.SEED, self.SEED.replace("0.1952568208298091", "195.2568208298091"))
        self.assertTrue(valid, why)
        self.assertIn("[-720, 720] deg", why)

    def test_an_angle_beyond_the_readers_range_or_a_length_x1000_is_not(self):
        self.assertFalse(judge("calibrated_model", self.SEED, self.SEED.replace("0.1952568208298091", "1000"))[0])
        self.assertFalse(judge("calibrated_model", self.SEED, self.SEED.replace("j2.a_mm: 0.5", "j2.a_mm: 500"))[0])


class NotValidInputs(unittest.TestCase):
    """The other two of seed 36's four are not valid inputs: the readers refuse them now, the judge does not
    excuse them."""

    def test_a_check_distance_of_1e_300_m_is_not_explained(self):
        seed = '{"check_distances": [{"dot_a": 1, "dot_b": 2, "length_m": 0.13219480342976214}]}'
        self.assertFalse(judge("setup_json", seed, seed.replace("0.13219480342976214", "1e-300"))[0])

    def test_a_flange_48_m_from_the_base_is_not_explained(self):
        seed = "x: 0.7169496300523684\ny: 0.00330346692205527\nz: 0.853313460465923\n"
        self.assertFalse(judge("ros_pose", seed, seed.replace("0.853313460465923", "48.891259886400817"))[0])


if __name__ == "__main__":
    unittest.main()
