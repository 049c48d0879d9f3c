"""scripts/map_scenes_summary.py: the README's table from map_scenes.sh's rows.

Run by CTest (map_scenes_summary_test) with Debian's python3; stdlib only.
"""
import os
import subprocess
import sys
import tempfile
import unittest

SUMMARY = os.path.join(os.path.dirname(__file__), "..", "..", "scripts", "map_scenes_summary.py")


def row(scene, seed, samples, cvs, right, worst, rmse, bnd=0.3, miss=0.4):
    return f"{scene}\t{seed}\t{samples}\t{cvs}\t{right}\t{worst}\t{rmse}\t{bnd}\t{miss}\n"


def summarise(rows):
    with tempfile.NamedTemporaryFile("w", suffix=".tsv", delete=False) as f:
        f.write("".join(rows))
        path = f.name
    try:
        return subprocess.run([sys.executable, SUMMARY, path], capture_output=True, text=True, check=False)
    finally:
        os.unlink(path)


class MapScenesSummaryTest(unittest.TestCase):
    def test_mean_worst_seed_and_goals_per_scene(self):
        out = summarise([
            row("plate", 1, 148, 99, 0.9958, 0.9907, 0.0091),
            row("plate", 2, 148, 99, 0.9970, 0.9930, 0.0077),
        ])
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("| plate | 148 (1.49) | 99.64 (99.58) % | 99.2 (99.1) % | 0.0084 | 0.30 / 0.40 | 2 of 2 |",
                      out.stdout)
        self.assertIn("Goals met on 2 of 2 scene-seeds.", out.stdout)

    def test_each_goal_is_checked_and_the_bottle_needs_99_5(self):
        out = summarise([
            row("bottle", 3, 123, 82, 0.9940, 0.9425, 0.0287),    # right 99.40 < 99.5: missed
            row("plate", 1, 148, 99, 0.9958, 0.8400, 0.0091),     # a region under 85 %
            row("plate", 2, 148, 99, 0.9958, 0.9900, 0.0310),     # mu RMSE over 0.03
            row("plate", 3, 149, 99, 0.9958, 0.9900, 0.0090),     # 149 > 1.5 x 99 samples
            row("dotted_egg", 1, 243, 162, 0.9700, 0.8500, 0.0300),  # every goal met at its edge
        ])
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("Goals met on 1 of 5 scene-seeds.", out.stdout)
        self.assertIn("Missed: bottle seed 3, plate seed 1, plate seed 2, plate seed 3.", out.stdout)

    def test_a_malformed_row_is_an_error_naming_its_line(self):
        short = summarise([row("plate", 1, 148, 99, 0.9958, 0.9907, 0.0091), "plate\t2\t148\n"])
        self.assertNotEqual(short.returncode, 0)
        self.assertIn(":2: 3 fields, expected 9", short.stderr)
        not_a_number = summarise([row("plate", 1, 148, 99, "abc", 0.9907, 0.0091)])
        self.assertNotEqual(not_a_number.returncode, 0)
        self.assertIn(":1: could not convert string to float: 'abc'", not_a_number.stderr)
        self.assertNotIn("Traceback", not_a_number.stderr)

    def test_no_rows_is_an_error(self):
        out = summarise([])
        self.assertNotEqual(out.returncode, 0)
        self.assertIn("no rows", out.stderr)


if __name__ == "__main__":
    unittest.main()
