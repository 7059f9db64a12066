#!/usr/bin/python3
"""Tests of scripts/check_file_names.py: a header named after none of its classes is listed; one
named after its class, or holding only free functions and plain structs, passes; enums, error
types, nested and forward-declared classes are not main types; a .cc of src/ with no header of
its name is listed.

Run from the repository root:  /usr/bin/python3 -m unittest discover -s test/python -v
Needs nothing built: the repository is a fake in a temporary folder.
"""
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..')
SCRIPT = os.path.join(REPO, 'scripts', 'check_file_names.py')

HEADERS = {
    # Named after its class, with the structs it takes and gives.
    'scene_3d.h': 'namespace pkg {\nstruct Scene3DParams { int a = f(1); };\nclass Scene3D {\n'
                  ' public:\n  class Nested {};\n  void run();\n};\n}  // namespace pkg\n',
    # Free functions, plain data, an enum class and an error type: named after what they do.
    'map_loading.h': 'namespace pkg {\nenum class MapMode { kTrinary };\nstruct MapInfo { int w; };\n'
                     'class MapLoadError : public std::runtime_error {\n  using runtime_error::runtime_error;\n};\n'
                     'class Forward;\nMapInfo loadMap(const char* path);\n}  // namespace pkg\n',
    # Named after a struct while its class is the main type.
    'widget_status.h': 'namespace pkg {\nstruct WidgetStatus { int n; };\n// class InAComment {};\n'
                       'class WidgetHealth {\n public:\n  WidgetStatus status() const;\n};\n'
                       '}  // namespace pkg\n',
}


class CheckFileNamesTest(unittest.TestCase):
    def setUp(self):
        self.root = tempfile.mkdtemp(prefix='pf_file_names_test_')
        for name, text in HEADERS.items():
            path = os.path.join(self.root, 'include', 'pkg', 'core', name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, 'w', encoding='utf-8') as f:
                f.write(text)
        # The implementation of scene_3d.h, and one left behind by a rename of its header.
        for name in ('scene_3d.cc', 'scene_maker.cc'):
            path = os.path.join(self.root, 'src', 'core', name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, 'w', encoding='utf-8') as f:
                f.write('namespace pkg {\nvoid Scene3D::run() {}\n}  // namespace pkg\n')

    def tearDown(self):
        shutil.rmtree(self.root, ignore_errors=True)

    def test_lists_only_the_file_named_after_none_of_its_classes(self):
        result = subprocess.run([sys.executable, SCRIPT, self.root], capture_output=True, text=True)
        self.assertEqual(result.returncode, 1, result.stdout + result.stderr)
        self.assertEqual(result.stdout.splitlines(),
                         ['include/pkg/core/widget_status.h: named after none of its classes (WidgetHealth)',
                          'src/core/scene_maker.cc: no header of its name and no class it is named after',
                          'check_file_names: 2 of 4 files not named after their main type'])

    def test_passes_once_renamed(self):
        core = os.path.join(self.root, 'include', 'pkg', 'core')
        os.rename(os.path.join(core, 'widget_status.h'), os.path.join(core, 'widget_health.h'))
        os.remove(os.path.join(self.root, 'src', 'core', 'scene_maker.cc'))
        result = subprocess.run([sys.executable, SCRIPT, self.root], capture_output=True, text=True)
        self.assertEqual(result.returncode, 0, result.stdout + result.stderr)


if __name__ == '__main__':
    unittest.main()
