#!/usr/bin/env python3
"""Every relative link of the project's Markdown documentation leads somewhere.

Checks the inline links and images, [text](target) and ![alt](target), and the
reference definitions, [id]: target, of README.md, docs/**/*.md (not
docs/report/cache/), bench/README.md, deploy/README.md, fuzz/README.md and
proto/CHANGELOG.md under the repository root given:

  - the target file or folder must exist, relative to the linking file (a
    target starting with '/' is relative to the repository root, as on GitHub);
  - a '#anchor' into a Markdown file (or '#anchor' alone: the same file) must be
    the GitHub slug of one of its headings, or an explicit <a name>/id anchor.

Links with a scheme (http:, https:, mailto:, ...) are not checked, nor anything
inside fenced code blocks or inline code spans. Prints "checked N links in M
files" and exits 0, or prints one line per broken link, file:line: target
(reason), and exits 1; exits 2 for bad usage.
"""
import os
import re
import sys
import unicodedata
import urllib.parse

FIXED_FILES = ('README.md', 'bench/README.md', 'deploy/README.md', 'fuzz/README.md', 'proto/CHANGELOG.md')
DOCS_DIR = 'docs'
SKIPPED_DIRS = ('docs/report/cache',)

FENCE = re.compile(r'^ {0,3}(`{3,}|~{3,})')
HEADING = re.compile(r'^ {0,3}(#{1,6})[ \t]+(.*?)[ \t]*#*[ \t]*$')
SETEXT_UNDERLINE = re.compile(r'^ {0,3}(=+|-+)[ \t]*$')
HTML_ANCHOR = re.compile(r'<a\s[^>]*?(?:name|id)\s*=\s*"([^"]+)"', re.IGNORECASE)
CODE_SPAN = re.compile(r'(`+)(.+?)\1')
# [text](target "title") or ![alt](target); the text may hold one level of brackets.
INLINE_LINK = re.compile(
    r'!?\[(?:[^\[\]]|\[[^\[\]]*\])*\]'
    r'\(\s*(<[^>\n]*>|(?:[^()\s]|\([^()\s]*\))+)(?:\s+(?:"[^"]*"|\'[^\']*\'|\([^()]*\)))?\s*\)')
REFERENCE_DEFINITION = re.compile(r'^ {0,3}\[[^\]]+\]:\s*(<[^>]*>|\S+)')
SCHEME = re.compile(r'^[A-Za-z][A-Za-z0-9+.-]*:')


def markdown_files(root):
    """The documentation files to check, as paths relative to root, sorted."""
    found = [path for path in FIXED_FILES if os.path.isfile(os.path.join(root, path))]
    docs = os.path.join(root, DOCS_DIR)
    for folder, subfolders, files in os.walk(docs):
        relative_folder = os.path.relpath(folder, root).replace(os.sep, '/')
        subfolders[:] = sorted(
            d for d in subfolders if f'{relative_folder}/{d}' not in SKIPPED_DIRS and not d.startswith('.'))
        found.extend(f'{relative_folder}/{name}' for name in sorted(files) if name.endswith('.md'))
    return sorted(set(found))


def github_slug(heading_text):
    """GitHub's anchor for a heading: the rendered text lower-cased, every character
    that is not a letter, mark, digit, connector (_), space or hyphen dropped, and
    spaces made hyphens."""
    text = re.sub(r'!?\[([^\]]*)\]\([^)]*\)', r'\1', heading_text)  # links and images: their text
    text = re.sub(r'<[^>]+>', '', text)  # inline HTML tags
    text = text.strip().lower()
    kept = []
    for ch in text:
        category = unicodedata.category(ch)
        if category[0] in 'LMN' or category == 'Pc' or ch in ' -':
            kept.append(ch)
    return ''.join(kept).replace(' ', '-')


def scan(text):
    """(links, anchors): the links outside code as (line number, target), and the
    anchors the file defines (heading slugs with GitHub's -1, -2 suffixes for
    repeats, and explicit HTML anchors)."""
    links, anchors, slug_counts = [], set(), {}
    fence = None
    previous = ''

    def add_heading(title):
        slug = github_slug(title)
        count = slug_counts.get(slug, 0)
        slug_counts[slug] = count + 1
        anchors.add(slug if count == 0 else f'{slug}-{count}')

    for number, line in enumerate(text.splitlines(), start=1):
        opening = FENCE.match(line)
        if fence is not None:
            if opening and opening.group(1)[0] == fence[0] and len(opening.group(1)) >= len(fence) \
                    and not line.strip()[len(opening.group(1)):].strip():
                fence = None
            previous = ''
            continue
        if opening:
            fence = opening.group(1)
            previous = ''
            continue
        heading = HEADING.match(line)
        if heading:
            add_heading(heading.group(2))
        elif previous.strip() and SETEXT_UNDERLINE.match(line) and not previous.startswith((' ' * 4, '\t')):
            add_heading(previous.strip())
        anchors.update(HTML_ANCHOR.findall(line))
        outside_code = CODE_SPAN.sub(lambda m: ' ' * len(m.group(0)), line)
        for match in INLINE_LINK.finditer(outside_code):
            links.append((number, match.group(1)))
        definition = REFERENCE_DEFINITION.match(outside_code)
        if definition:
            links.append((number, definition.group(1)))
        previous = line
    return links, anchors


def check(root):
    """(number of links checked, files, broken): broken lists (file, line, target, reason)."""
    files = markdown_files(root)
    anchors_of = {}

    def anchors(path):
        if path not in anchors_of:
            with open(os.path.join(root, path), encoding='utf-8') as f:
                anchors_of[path] = scan(f.read())[1]
        return anchors_of[path]

    checked, broken = 0, []
    for source in files:
        with open(os.path.join(root, source), encoding='utf-8') as f:
            links, own_anchors = scan(f.read())
        anchors_of[source] = own_anchors
        for line, raw in links:
            target = raw[1:-1].strip() if raw.startswith('<') else raw
            if not target or SCHEME.match(target):
                continue
            checked += 1
            path_part, _, anchor = target.partition('#')
            path_part = urllib.parse.unquote(path_part.split('?')[0])
            if path_part:
                base = root if path_part.startswith('/') else os.path.join(root, os.path.dirname(source))
                resolved = os.path.normpath(os.path.join(base, path_part.lstrip('/')))
                relative = os.path.relpath(resolved, root).replace(os.sep, '/')
                if relative.startswith('../') or relative == '..':
                    broken.append((source, line, raw, 'outside the repository'))
                    continue
                if not os.path.exists(resolved):
                    broken.append((source, line, raw, 'no such file'))
                    continue
            else:
                relative = source
            if anchor and relative.endswith('.md') and os.path.isfile(os.path.join(root, relative)):
                if urllib.parse.unquote(anchor).lower() not in anchors(relative):
                    broken.append((source, line, raw, f'no heading with anchor #{anchor} in {relative}'))
    return checked, files, broken


def main(argv):
    if len(argv) != 2 or not os.path.isdir(argv[1]):
        print(f'usage: {os.path.basename(argv[0])} REPOSITORY_ROOT', file=sys.stderr)
        return 2
    checked, files, broken = check(argv[1])
    for source, line, target, reason in broken:
        print(f'{source}:{line}: {target} ({reason})')
    if broken:
        print(f'{len(broken)} broken of {checked} links in {len(files)} files')
        return 1
    print(f'checked {checked} links in {len(files)} files')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
