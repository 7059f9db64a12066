#!/usr/bin/python3
"""Tests of scripts/count_test_results.py: each gtest case, rostest test node and pytest case
counts once; a rostest launch file counts only when it failed; a failed case is named with the
first lines of its message, from the assertion on for a rosunit traceback.

Run from the repository root:  /usr/bin/python3 -m unittest discover -s test/python -v
Needs nothing built: the result files are fakes in a temporary folder.
"""
import os
import shutil
import subprocess
import tempfile
import unittest

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..')
SCRIPT = os.path.join(REPO, 'scripts', 'count_test_results.py')

ROSUNIT_FAILED = '''<testsuite tests="1"><testcase classname="__main__.PoseCheckerTest"
name="test_pose_checker"><failure type="AssertionError">Traceback (most recent call last):
  File "pose_checker.py", line 129, in test_pose_checker
    self.assertTrue(ok, msg)
AssertionError: False is not true : FAILED: position RMSE 0.045 m &gt; 0.040 m
pose_checker [track]: n=1217 position error RMSE 0.045 m
  confidently wrong: 0 of 147
line four
line five</failure></testcase></testsuite>'''
ROSUNIT_PASSED = '<testsuite><testcase classname="c" name="test_ok"/></testsuite>'
# A rostest launch says "passed" even when its test node failed.
ROSTEST_PASSED = '<testsuite><testcase classname="c" name="launch"/></testsuite>'
GTEST = '''<testsuites><testsuite name="S"><testcase name="a" classname="S"/>
<testcase name="b" classname="S"><failure message="test.cc:12&#x0A;Expected: 1.0 &lt; 0.5">
detail</failure></testcase><testcase name="c" classname="S"><skipped/></testcase>
</testsuite></testsuites>'''


class CountTestResultsTest(unittest.TestCase):
    def setUp(self):
        self.root = tempfile.mkdtemp(prefix='pf_count_results_test_')
        files = {'rosunit-track.xml': ROSUNIT_FAILED, 'rosunit-ok.xml': ROSUNIT_PASSED,
                 'rostest-track.xml': ROSTEST_PASSED, 'gtest-core.xml': GTEST,
                 'other.xml': ROSUNIT_FAILED}
        for name, text in files.items():
            with open(os.path.join(self.root, name), 'w') as f:
                f.write(text)

    def tearDown(self):
        shutil.rmtree(self.root)

    def run_script(self):
        return subprocess.run(['/usr/bin/python3', SCRIPT, self.root], capture_output=True,
                              text=True, check=True)

    def test_counts_each_case_once(self):
        # gtest a (passed) and b (failed), c skipped; rosunit ok and track; the
        # passing rostest launch and the file of no known kind count in neither.
        self.assertEqual(self.run_script().stdout.split(), ['2', '2'])

    def test_a_failure_is_named_with_its_reason(self):
        err = self.run_script().stderr.splitlines()
        track = err.index('FAILED: rosunit-track.xml __main__.PoseCheckerTest.test_pose_checker')
        self.assertEqual(err[track + 1].strip(),
                         'AssertionError: False is not true : FAILED: position RMSE 0.045 m > 0.040 m')
        self.assertEqual(err[track + 4].strip(), 'line four')
        self.assertNotIn('    line five', err, 'at most four lines of a message')
        gtest = err.index('FAILED: gtest-core.xml S.b')
        self.assertEqual([line.strip() for line in err[gtest + 1:gtest + 3]],
                         ['test.cc:12', 'Expected: 1.0 < 0.5'])


if __name__ == '__main__':
    unittest.main()
