#!/usr/bin/python3
"""Counts passed and failed test cases in catkin's JUnit result files.

catkin_test_results adds up the "tests" attributes of every file, which counts
each gtest case twice (its suite and the whole run both carry it) and each
rostest twice (once in rostest-*.xml, once in the test node's rosunit-*.xml).
Here every gtest case, every rostest's test node and every pytest case
(pytest-*.xml, scripts/test.sh's) counts once; skipped ones count in neither.
usage: count_test_results.py RESULTS_DIR      prints "PASSED FAILED"
"""
import glob
import os
import sys
import xml.etree.ElementTree as ET


def count(results_dir):
    passed = failed = 0
    for path in sorted(glob.glob(os.path.join(results_dir, '**', '*.xml'), recursive=True)):
        name = os.path.basename(path)
        # gtest-*, pytest-*: one case per test. rosunit-*: the test node of a
        # rostest, which holds its verdict. rostest-*: only the launch itself (it
        # says "passed" even when its test node failed), so only its failures count.
        if not name.startswith(('gtest-', 'pytest-', 'rosunit-', 'rostest-')):
            continue
        try:
            cases = list(ET.parse(path).getroot().iter('testcase'))
        except ET.ParseError as e:
            print('%s: unreadable result file: %s' % (path, e), file=sys.stderr)
            failed += 1
            continue
        for case in cases:
            if case.find('skipped') is not None:
                continue
            bad = case.find('failure') is not None or case.find('error') is not None
            if name.startswith('rostest-') and not bad:
                continue
            failed += bad
            passed += not bad
            if bad:
                print('FAILED: %s %s.%s' % (name, case.get('classname'), case.get('name')),
                      file=sys.stderr)
    return passed, failed


if __name__ == '__main__':
    p, f = count(sys.argv[1])
    print(p, f)
