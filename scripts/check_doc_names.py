#!/usr/bin/python3
"""check_doc_names.py [ROOT]: every code name the manual puts in backticks exists in the code.

Guards against docs drift: a file, type or function renamed or removed in the code while README.md
or docs/**/*.md still names it. ROOT is the repository (default: the one holding this script).

What is checked, in inline `code` outside fenced blocks:
  - a path into the repository (first part one of PATH_ROOTS; core/, ros/ and sim/ are read under
    include/PACKAGE/ and src/): the file or folder must exist (a * matches any name);
  - a file name with a source extension (SOURCE_EXTENSIONS): a file of that name must exist;
  - a name (snake_case, CamelCase, camelCase, ALL_CAPS), also qualified (Type::member), called
    (name() or name(...)) or a gtest Suite.Name: each part must be a file or folder stem of the
    repository, or a word of the code outside its comments. The code is every text file under
    CODE_ROOTS and CMakeLists.txt (this check and its test left out, since they name made-up and
    foreign names): its definitions, its uses and its strings, which hold the
    parameter, topic, service, field and check names the manual also names. A name that is
    nowhere in the code, or only in a comment or a Markdown file, is what this reports.
  - an environment variable or constant (PF_WS): a word of the code, as above;
  - a command (a span with spaces): its repository paths and source file names, as above, and its
    program when it is this package's (pf_*, or the one after `rosrun pf_localization`).
Not checked: options (-x, --x), absolute or home paths (/x, ~x, ../x), patterns (x_*.py),
placeholders (<x>, $X, a part in capitals such as X.sh), a span with = or :, numbers, a name
starting with _ (a suffix such as `_yaw`), file names of data or outputs (.bag, .yaml, .png, ...),
and other libraries' and tools' names (EXTERNAL, EXTERNAL_NAMESPACES).

Prints each missing name as DOC:LINE; exit 1 if any, else 0 with a one-line summary.
"""
import glob
import os
import re
import sys

DOCS = ['README.md', 'docs/**/*.md']
CODE_ROOTS = ['include', 'src', 'test', 'scripts', 'bench', 'launch', 'config', 'cfg', 'msg']
PATH_ROOTS = CODE_ROOTS + ['docs', 'maps', 'bags', 'rviz', 'core', 'ros', 'sim']
SOURCE_EXTENSIONS = {'.h', '.hpp', '.cc', '.cpp', '.py', '.sh', '.launch', '.test', '.msg', '.srv', '.cfg'}
CODE_EXTENSIONS = SOURCE_EXTENSIONS | {'.bash', '.yaml', '.yml', '.xml', '.txt', '.cmake'}

C_COMMENT = re.compile(r'("(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\')|//[^\n]*|/\*.*?\*/', re.S)
HASH_COMMENT = re.compile(r'("(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\')|#[^\n]*')
XML_COMMENT = re.compile(r'()<!--.*?-->', re.S)
FENCE = re.compile(r'^ *(```|~~~).*?^ *\1', re.S | re.M)
SPAN = re.compile(r'`([^`]+)`')
NAME = re.compile(r'[A-Za-z][A-Za-z0-9_]*')
QUALIFIED = re.compile(r'[A-Za-z]\w*(?:::~?\w+)*(?:\([^()]*\))?')
GTEST = re.compile(r'[A-Z]\w*\.[A-Z]\w*')
# Names the manual rightly gives that belong to others: a profiler, and libm's float functions
# named as what the project does not call. Names qualified by another library's namespace are
# left out by EXTERNAL_NAMESPACES.
EXTERNAL = {'perf', 'sinf', 'cosf'}
EXTERNAL_NAMESPACES = ('std::', 'ros::', 'tf2::', 'tf2_ros::')


def repository_files(root):
    """Paths (relative, with /) of the repository's files, hidden folders left out."""
    found = []
    for folder, dirs, files in os.walk(root):
        dirs[:] = [d for d in dirs if not d.startswith('.') and d != 'site']
        found += [os.path.relpath(os.path.join(folder, f), root).replace(os.sep, '/') for f in files]
    return found


def code_text(path):
    """The file's text with its comments blanked (strings kept), or '' for a file that is not code."""
    name = os.path.basename(path)
    ext = os.path.splitext(name)[1]
    try:
        with open(path, encoding='utf-8') as f:
            text = f.read()
    except (UnicodeDecodeError, OSError):
        return ''
    if ext in ('.h', '.hpp', '.cc', '.cpp'):
        pattern = C_COMMENT
    elif ext in ('.launch', '.test', '.xml'):
        pattern = XML_COMMENT
    elif ext in CODE_EXTENSIONS or name == 'CMakeLists.txt' or text.startswith('#!'):
        pattern = HASH_COMMENT
    else:
        return ''
    return pattern.sub(lambda m: m.group(1) or ' ', text)


class Code:
    """What the repository holds: its files, folders and the words of its code."""

    def __init__(self, root):
        self.root = root
        self.files = repository_files(root)
        self.folders = {os.path.dirname(f) for f in self.files}
        self.folders |= {'/'.join(f.split('/')[:i]) for f in self.folders for i in range(1, f.count('/') + 1)}
        self.basenames = {os.path.basename(f) for f in self.files}
        self.stems = {os.path.splitext(b)[0] for b in self.basenames}
        self.stems |= {os.path.basename(d) for d in self.folders}
        self.words = set()
        for f in self.files:
            if (f.split('/')[0] in CODE_ROOTS or f == 'CMakeLists.txt') and 'check_doc_names' not in f:
                self.words.update(NAME.findall(code_text(os.path.join(root, f))))

    def has_path(self, path):
        path = path.rstrip('/')
        if path.split('/')[0] in ('core', 'ros', 'sim'):  # read under include/PACKAGE/ or src/
            return any(glob.glob(os.path.join(self.root, base, path)) for base in ('include/*', 'src'))
        return bool(glob.glob(os.path.join(self.root, path)))

    def has_name(self, name):
        return name in self.stems or name in self.words


def is_path(word):
    return '/' in word and word.split('/')[0] in PATH_ROOTS


def placeholder(word):
    """A made-up part such as X.sh, FILE or <workspace>, or a pattern such as test_*.py: nothing to
    look up."""
    return (any(re.fullmatch(r'[A-Z][A-Z0-9_]*', part) for part in re.split(r'[/.]', word)) or
            '<' in word or '*' in word)


def missing_in_command(words, code):
    """The names a command (a span with spaces) gives that the code does not have: its repository
    paths and source files, and its program when it is this package's (pf_*, or after `rosrun
    pf_localization`). Everything else in a command is an option, a value or another program."""
    missing = []
    for i, w in enumerate(words):
        after_rosrun = words[max(i - 2, 0):i] == ['rosrun', 'pf_localization']
        program = (i == 0 and re.fullmatch(r'pf_\w+', w)) or after_rosrun
        if placeholder(w) or w.startswith(('-', '/', '~', '.', '$')):
            continue
        if is_path(w) or os.path.splitext(w)[1] in SOURCE_EXTENSIONS or program:
            missing += missing_names(w, code)
    return missing


def missing_names(span, code):
    """The names in one backticked span that the code does not have ([] when none or not a code name)."""
    span = span.strip()
    if re.search(r'\s', span):
        return missing_in_command(span.split(), code)
    if span in EXTERNAL or span.startswith(EXTERNAL_NAMESPACES):
        return []
    if re.fullmatch(r'[A-Z][A-Z0-9]*(_[A-Z0-9]+)+', span):  # an environment variable or a constant
        return [] if code.has_name(span) else [span]
    if span.startswith(('-', '/', '~', '.', '$', '_')) or placeholder(span) or re.search(r'=|:\s', span):
        return []
    if is_path(span):
        return [] if code.has_path(span) else [span]
    if '/' in span:
        return []
    ext = os.path.splitext(span)[1]
    if ext and not GTEST.fullmatch(span):
        if ext in SOURCE_EXTENSIONS:
            return [] if span in code.basenames else [span]
        return []
    if not (QUALIFIED.fullmatch(span) or GTEST.fullmatch(span)):
        return []
    names = NAME.findall(span.split('(')[0])
    return [span] if any(not code.has_name(n) for n in names) else []


def doc_spans(text):
    """(line, span) for each inline code span of a Markdown text, fenced blocks left out."""
    text = FENCE.sub(lambda m: '\n' * m.group(0).count('\n'), text)
    for m in SPAN.finditer(text):
        yield text.count('\n', 0, m.start()) + 1, m.group(1)


def main(argv):
    if len(argv) > 2 or argv[1:2] in (['-h'], ['--help']):
        print(__doc__, file=sys.stderr)
        return 2
    root = os.path.abspath(argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(__file__), '..'))
    code = Code(root)
    docs = sorted({d for pattern in DOCS for d in glob.glob(os.path.join(root, pattern), recursive=True)})
    missing, spans = [], 0
    for doc in docs:
        with open(doc, encoding='utf-8') as f:
            for line, span in doc_spans(f.read()):
                spans += 1
                for name in missing_names(span, code):
                    where = '%s:%d' % (os.path.relpath(doc, root), line)
                    missing.append('%s: `%s` is not in the code' % (where, name))
    for m in missing:
        print(m)
    if missing:
        print('check_doc_names: %d names in backticks are not in the code' % len(missing))
        return 1
    print('check_doc_names: %d backticked spans in %d docs, every code name found' % (spans, len(docs)))
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
