#!/usr/bin/python3
"""check_doc_links.py SITE REPO: every internal link of the built manual and of README.md resolves.

SITE is the folder `mkdocs build` wrote (use_directory_urls: false). For every page, each <a href>
and <img src> that is not absolute (no scheme, no leading /) must name a file of the site, and a
#fragment must be the id of an element of that page. mkdocs --strict already warns about links to
missing pages; it does not look at anchors, which this does. README.md, which is not part of the
manual, is checked too: its links to files must exist in REPO, and those into docs/*.md#anchor must
name an anchor of the built page. Prints each broken link with its page; exit 1 if any.
"""
import html.parser
import os
import re
import sys
import urllib.parse


class Page(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.ids, self.links = set(), []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if a.get('id'):
            self.ids.add(a['id'])
        if tag == 'a' and a.get('name'):
            self.ids.add(a['name'])
        for key in ('href', 'src'):
            if tag in ('a', 'img') and a.get(key):
                self.links.append(a[key])


def parse(path):
    p = Page()
    with open(path, encoding='utf-8') as f:
        p.feed(f.read())
    return p


def internal(link):
    u = urllib.parse.urlsplit(link)
    return not (u.scheme or u.netloc or link.startswith('/') or link.startswith('mailto:'))


def main(argv):
    if len(argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    site, repo = (os.path.abspath(a) for a in argv[1:])
    pages = {}
    for root, _, files in os.walk(site):
        for name in files:
            if name.endswith('.html'):
                path = os.path.join(root, name)
                pages[path] = parse(path)
    bad, checked = [], 0
    for path, page in sorted(pages.items()):
        if os.path.relpath(path, site).startswith(('search', '404')):
            continue
        for link in page.links:
            if not internal(link):
                continue
            u = urllib.parse.urlsplit(link)
            target = os.path.normpath(os.path.join(os.path.dirname(path), urllib.parse.unquote(u.path))) \
                if u.path else path
            checked += 1
            if not os.path.exists(target):
                bad.append('%s: %s: no such file in the site' % (os.path.relpath(path, site), link))
            elif u.fragment and target.endswith('.html') and u.fragment not in pages[target].ids:
                bad.append('%s: %s: no anchor #%s there' % (os.path.relpath(path, site), link, u.fragment))
    # README.md: [text](target) links, checked against the repository and the built pages.
    readme = open(os.path.join(repo, 'README.md'), encoding='utf-8').read()
    readme = re.sub(r'```.*?```', '', readme, flags=re.S)
    for link in re.findall(r'\]\(([^)\s]+)\)', readme):
        if not internal(link):
            continue
        checked += 1
        u = urllib.parse.urlsplit(link)
        if u.path and not os.path.exists(os.path.join(repo, u.path)):
            bad.append('README.md: %s: no such file' % link)
            continue
        if u.fragment:
            rel = os.path.relpath(os.path.join(repo, u.path), os.path.join(repo, 'docs'))
            built = os.path.join(site, re.sub(r'\.md$', '.html', rel))
            if built not in pages:
                bad.append('README.md: %s: an anchor outside the manual cannot be checked' % link)
            elif u.fragment not in pages[built].ids:
                bad.append('README.md: %s: no anchor #%s there' % (link, u.fragment))
    for line in bad:
        print(line)
    print('check_doc_links: %d internal links and anchors checked in %d pages and README.md, %d broken'
          % (checked, len(pages), len(bad)))
    return 1 if bad or not checked else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
