#!/usr/bin/python3
"""List C++ function bodies longer than a limit (default 80 lines) in the given files.

usage: long_functions.py [--max N] FILE...

A function body is a brace block opened at the end of a line that looks like a
function head (a name and a parameter list, not a control statement, a class,
a namespace or a lambda assigned inside another body), at namespace or class
level. It counts the lines from the head's line to the closing brace. Exit
status 1 when any is longer, so a check can call it; 0 otherwise.
"""
import re
import sys

HEAD = re.compile(r'^\s*(?:[\w:<>,~*&\s]+?\s+)?[~\w:]+\s*\([^;]*\)\s*(?:const\s*)?(?:override\s*)?'
                  r'(?:noexcept\s*)?(?::[^{]*)?\{\s*$')
CONTROL = re.compile(r'^\s*(?:if|for|while|switch|catch|else|do|return)\b')


def strip(line):
    line = re.sub(r'"(?:\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(?:\\.|[^'\\])*'", "''", line)
    return line.split('//')[0]


def long_functions(path, limit):
    lines = open(path, encoding='utf-8').read().split('\n')
    found, depth, stack = [], 0, []
    head_buffer = ''
    for number, raw in enumerate(lines, 1):
        line = strip(raw)
        head_buffer = (head_buffer + ' ' + line.strip()) if head_buffer else line.strip()
        for ch in line:
            if ch == '{':
                is_function = (not any(s[1] for s in stack) and HEAD.match(head_buffer) is not None
                               and not CONTROL.match(head_buffer)
                               and not re.match(r'^\s*(class|struct|namespace|enum|union)\b', head_buffer))
                name = re.findall(r'([~\w:]+)\s*\(', head_buffer)
                stack.append((number, is_function, name[0] if name else '?'))
            elif ch == '}':
                if stack:
                    start, is_function, name = stack.pop()
                    if is_function and number - start + 1 > limit:
                        found.append((path, start, number - start + 1, name))
        if line.strip().endswith((';', '{', '}')) or not line.strip():
            head_buffer = ''
    return found


def main(argv):
    limit = 80
    if argv[:1] == ['--max']:
        limit, argv = int(argv[1]), argv[2:]
    found = []
    for path in argv:
        found += long_functions(path, limit)
    for path, start, length, name in found:
        print('%s:%d: %s is %d lines (at most %d)' % (path, start, name, length, limit))
    return 1 if found else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
