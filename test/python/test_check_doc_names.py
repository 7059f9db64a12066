#!/usr/bin/python3
"""Tests of scripts/check_doc_names.py: it finds a name the manual gives that the code does not
have, with its doc and line, and passes the names the code has (a check that cannot fail would
guard nothing).

Run from the repository root:  /usr/bin/python3 -m unittest discover -s test/python -v
Needs nothing built: the repository is a fake in a temporary folder.
"""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..', 'scripts', 'check_doc_names.py')


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, 'w', encoding='utf-8') as f:
        f.write(text)


class CheckDocNamesTest(unittest.TestCase):
    def setUp(self):
        self.root = tempfile.mkdtemp(prefix='pf_doc_names_test_')
        write(os.path.join(self.root, 'include/pkg/core/util/bin_table.h'),
              '// A comment naming old_helper does not make it exist.\n'
              'struct BinTable { int lookUp(int key) const; };\n'
              'const char* kParameter = "max_particles";\n')
        write(os.path.join(self.root, 'README.md'), 'See `bin_table` and `BinTable::lookUp()`.\n')

    def tearDown(self):
        shutil.rmtree(self.root, ignore_errors=True)

    def run_check(self, doc):
        write(os.path.join(self.root, 'docs/how-it-works/util.md'), doc)
        return subprocess.run([sys.executable, SCRIPT, self.root], capture_output=True, text=True)

    def test_names_the_code_has_pass(self):
        result = self.run_check('# Utilities\n\n`bin_table` (`core/util/bin_table.h`) holds `BinTable`;\n'
                                '`max_particles` is a parameter, `--particles` an option, `/scan` a topic.\n'
                                '```\nvanished_table  # a fenced block is not read\n```\n')
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)
        self.assertIn('every code name found', result.stdout)

    def test_a_missing_name_fails_with_its_doc_and_line(self):
        result = self.run_check('# Utilities\n\n`bin_table` is here;\n'
                                '`vanished_table` and `old_helper` are gone,\n'
                                'so are `core/util/vanished_table.h` and `OldTable::lookUp`.\n')
        self.assertEqual(result.returncode, 1, result.stdout + result.stderr)
        lines = result.stdout.splitlines()
        for line, name in ((4, 'vanished_table'), (4, 'old_helper'), (5, 'core/util/vanished_table.h'),
                           (5, 'OldTable::lookUp')):
            self.assertIn('docs/how-it-works/util.md:%d: `%s` is not in the code' % (line, name), lines)
        self.assertEqual(len(lines), 5, result.stdout)  # the four and the summary: `bin_table` is found


if __name__ == '__main__':
    unittest.main()
