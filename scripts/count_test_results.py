#!/usr/bin/python3
"""Counts passed and failed test cases in catkin's JUnit result files.

catkin_test_results adds up the "tests" attributes of every file, which counts
each gtest case twice (its suite and the whole run both carry it) and each
rostest twice (once in rostest-*.xml, once in the test node's rosunit-*.xml).
Here every gtest case, every rostest's test node and every pytest case
(pytest-*.xml, scripts/test.sh's) counts once; skipped ones count in neither.
Each failed case is named on stderr with the first lines of its failure message
(a checker's verdict, an assertion), so that the end of the run says why.
usage: count_test_results.py RESULTS_DIR      prints "PASSED FAILED"
"""
import glob
import os
import sys
import xml.etree.ElementTree as ET


# How much of a failure message the verdict repeats: its first lines, each cut short.
FAILURE_LINES = 4
FAILURE_LINE_CHARS = 400


def failure_lines(case):
    """The first lines of a failed case's message: from the assertion on when the
    message is a Python traceback (rosunit's), else from its start (gtest's, pytest's)."""
    node = case.find('failure')
    if node is None:
        node = case.find('error')
    lines = [line.rstrip() for line in (node.get('message') or node.text or '').splitlines()
             if line.strip()]
    for i, line in enumerate(lines):
        if line.startswith(('AssertionError', 'Exception', 'Error')):
            lines = lines[i:]
            break
    return [line[:FAILURE_LINE_CHARS] for line in lines[:FAILURE_LINES]]


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
                for line in failure_lines(case):
                    print('    ' + line, file=sys.stderr)
    return passed, failed


if __name__ == '__main__':
    p, f = count(sys.argv[1])
    print(p, f)
