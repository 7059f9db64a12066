#!/usr/bin/python3
"""check_file_names.py [ROOT]: each C++ file is named after the main type it defines.

Guards that a file's name says what it holds: a reader looking for a type finds it in the file of
its name, in snake_case (DistanceField in distance_field.h). ROOT is the repository (default:
the one holding this script). The files are every header under include/, and every .cc under src/ that
has no header of its own path (src/X/Y.cc beside include/PACKAGE/X/Y.h); a .cc defining main() is
a program, named after its executable, and is left out. Such a .cc must define a class it is named
after: one that implements a header of another name (a rename that left it behind) is listed.

The rule, from the file's text with comments and strings blanked: its classes are the class
definitions at namespace level (not nested, not forward declarations, not error types: those
deriving from an exception). By the style the project follows, a class has behaviour and a struct
is passive data, so the main type of a file is one of its classes, and its structs and enums are
what the class takes and gives.
  - A file named after one of its classes passes (in snake_case: compared with underscores left
    out, so Scene3D fits scene_3d.h and Pose2 pose2.h).
  - A file with no class holds free functions and the plain data they take and give: it is to be
    named after what the functions do, which a script cannot judge, and passes.
  - Otherwise it is listed, with its classes, the most often named in the file and its .cc first.
ALLOWED lists files rightly named otherwise, each with its reason.

Prints each file listed, with why (its classes, the most often named first); exit 1 if any, else
0 with a one-line summary.
"""
import glob
import os
import re
import sys

COMMENT_OR_STRING = re.compile(r'"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'|//[^\n]*|/\*.*?\*/', re.S)
TYPE_HEAD = re.compile(r'\b(class|struct|union)\s+(?:\[\[[^\]]*\]\]\s*)?(\w+)(?:\s+final)?\s*(:[^;{]*)?\{')
ERROR_BASE = re.compile(r'exception|error', re.I)
NAMESPACE = re.compile(r'\bnamespace\b[\w:\s]*\{')
ENUM_HEAD = re.compile(r'\benum(?:\s+class|\s+struct)?\s+\w+[^;{]*\{')
MAIN = re.compile(r'\bint\s+main\s*\(')

# File (relative to ROOT) -> why its name is right although it is not its main type's.
ALLOWED = {
    # The partition of the particles into blocks and slices is free functions (blockCount,
    # forEachBlock, reduceBlocks, sumBlocks, forEachSlice); BlockStreams is the blocks' random
    # streams, one more part of the same partition, not what the file is about.
    'include/pf_localization/core/filter/particle_blocks.h':
        'free functions of the particle blocks; BlockStreams is their random streams',
    # The simulator's path scripts: the PathScript a script file becomes (a struct: the data the
    # file is about), its parser, and PathPlayer, which plays one back.
    'include/pf_localization/sim/path_script.h':
        'the PathScript struct, its parser and its player',
}


def code(path):
    with open(path, encoding='utf-8') as f:
        text = COMMENT_OR_STRING.sub(' ', f.read())
    return re.sub(r'^\s*#.*$', '', text, flags=re.M)  # preprocessor lines


def closing(text, open_at):
    """Index just past the brace that closes the one at open_at."""
    depth = 0
    for i in range(open_at, len(text)):
        depth += {'{': 1, '}': -1}.get(text[i], 0)
        if depth == 0:
            return i + 1
    return len(text)


def classes_of(text):
    """The classes defined at namespace level that are not error types: [name]."""
    classes, i = [], 0
    while i < len(text):
        ns, enum, head = NAMESPACE.match(text, i), ENUM_HEAD.match(text, i), TYPE_HEAD.match(text, i)
        if ns:  # a namespace's inside is still namespace level
            i = ns.end()
        elif enum:
            i = closing(text, enum.end() - 1)
        elif head:
            if head.group(1) == 'class' and not ERROR_BASE.search(head.group(3) or ''):
                classes.append(head.group(2))
            i = closing(text, head.end() - 1)
        elif text[i] == '{':
            i = closing(text, i)
        else:
            i += 1
    return classes


def misnamed(path, implementation):
    """Why the file is named wrongly, or None when it is not."""
    text = code(path)
    if MAIN.search(text):
        return None
    classes = classes_of(text)
    stem = os.path.splitext(os.path.basename(path))[0].replace('_', '')
    if any(c.lower() == stem for c in classes):
        return None
    if path.endswith('.cc') and not classes:
        return 'no header of its name and no class it is named after'
    if not classes:
        return None
    both = text + (code(implementation) if implementation else '')
    classes.sort(key=lambda c: -len(re.findall(r'\b%s\b' % c, both)))
    return 'named after none of its classes (%s)' % ', '.join(classes)


def files(root):
    """(file, its .cc or None) for each header under include/ and each .cc of src/ without one."""
    pairs = []
    headers = glob.glob(os.path.join(root, 'include', '*', '**', '*.h'), recursive=True)
    implemented = set()
    for h in headers:
        rel = os.path.relpath(h, os.path.join(root, 'include'))
        cc = os.path.join(root, 'src', *rel.split(os.sep)[1:])[:-2] + '.cc'
        implemented.add(os.path.normpath(cc))
        pairs.append((h, cc if os.path.exists(cc) else None))
    for cc in glob.glob(os.path.join(root, 'src', '**', '*.cc'), recursive=True):
        if os.path.normpath(cc) not in implemented:
            pairs.append((cc, None))
    return sorted(pairs)


def main(argv):
    if len(argv) > 2 or argv[1:2] in (['-h'], ['--help']):
        print(__doc__, file=sys.stderr)
        return 2
    root = os.path.abspath(argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(__file__), '..'))
    pairs = files(root)
    wrong = []
    for path, implementation in pairs:
        rel = os.path.relpath(path, root)
        why = None if rel in ALLOWED else misnamed(path, implementation)
        if why:
            wrong.append('%s: %s' % (rel, why))
    for w in wrong:
        print(w)
    if wrong:
        print('check_file_names: %d of %d files not named after their main type' % (len(wrong), len(pairs)))
        return 1
    print('check_file_names: %d files, each named after its main type or holding free functions' % len(pairs))
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
