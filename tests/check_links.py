#!/usr/bin/env python3
"""Checks that every relative link and image in the project's Markdown files
resolves: the file exists, and an anchor (#...) names a heading of that file,
spelt as GitHub spells heading anchors. Links to http(s) and mailto are not
followed. Run from anywhere: python3 tests/check_links.py [FILE.md ...]
(default: every *.md that git tracks, or that is under the source tree).
Prints each broken link as FILE:LINE: target (reason) and exits 1 if any."""
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LINK = re.compile(r'!?\[(?:[^\]\\]|\\.)*\]\(([^()\s]+)(?:\s+"[^"]*")?\)')
FENCE = re.compile(r'^\s*(```|~~~)')


# Third-party assets copied unchanged, with their own READMEs and licences:
# their links point into the repositories they came from.
THIRD_PARTY = ('scenes/khronos/',)


def markdown_files():
    return [f for f in all_markdown_files() if not f.startswith(THIRD_PARTY)]


def all_markdown_files():
    try:
        out = subprocess.run(['git', 'ls-files', '--cached', '--others', '--exclude-standard', '*.md'],
                             cwd=ROOT, capture_output=True, text=True, check=True).stdout
        return sorted(set(out.split()))
    except (OSError, subprocess.CalledProcessError):
        found = []
        for d, dirs, files in os.walk(ROOT):
            dirs[:] = [x for x in dirs if x not in ('.git', 'build', 'out')]
            found += [os.path.relpath(os.path.join(d, f), ROOT) for f in files if f.endswith('.md')]
        return sorted(found)


def prose_lines(path):
    """(line number, text) of the lines outside fenced code, inline code removed."""
    fenced = False
    with open(path, encoding='utf-8') as f:
        for n, line in enumerate(f, 1):
            if FENCE.match(line):
                fenced = not fenced
                continue
            if not fenced:
                yield n, re.sub(r'`[^`]*`', '', line)


def slug(heading):
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to '-'."""
    text = re.sub(r'`', '', heading.strip().lower())
    text = re.sub(r'\[([^\]]*)\]\([^)]*\)', r'\1', text)
    text = ''.join(c for c in text if c.isalnum() or c in ' -_')
    return text.replace(' ', '-')


def anchors(path, cache={}):
    if path not in cache:
        seen, result = {}, set()
        fenced = False
        with open(path, encoding='utf-8') as f:
            for line in f:
                if FENCE.match(line):
                    fenced = not fenced
                m = None if fenced else re.match(r'^(#{1,6})\s+(.*?)\s*#*\s*$', line)
                if m:
                    s = slug(m.group(2))
                    k = seen.get(s, 0)
                    seen[s] = k + 1
                    result.add(s if k == 0 else '%s-%d' % (s, k))
        cache[path] = result
    return cache[path]


def check(rel):
    path = os.path.join(ROOT, rel)
    bad = []
    for n, line in prose_lines(path):
        for m in LINK.finditer(line):
            target = m.group(1)
            if re.match(r'^[a-z]+:', target):
                continue
            file_part, _, anchor = target.partition('#')
            dest = os.path.normpath(os.path.join(os.path.dirname(path), file_part)) if file_part else path
            if not os.path.exists(dest):
                bad.append('%s:%d: %s (no such file)' % (rel, n, target))
            elif anchor and dest.endswith('.md') and anchor not in anchors(dest):
                bad.append('%s:%d: %s (no heading with anchor #%s)' % (rel, n, target, anchor))
    return bad


def main(argv):
    files = argv or markdown_files()
    bad, links = [], 0
    for rel in files:
        bad += check(rel)
        links += sum(len(LINK.findall(t)) for _, t in prose_lines(os.path.join(ROOT, rel)))
    for b in bad:
        print(b)
    print('%d Markdown files, %d links, %d broken' % (len(files), links, len(bad)))
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
