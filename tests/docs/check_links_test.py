#!/usr/bin/env python3
"""The link check can fail: on a temporary tree with one good and one broken link
it exits 1 naming the broken one (file:line: target), and 0 once that link is
mended. Also: a broken anchor fails, while links in code, web links and GitHub's
slugs of headings with code, punctuation and repeats pass."""
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
CHECK = os.path.join(HERE, 'check_links.py')


def run(root):
    done = subprocess.run([sys.executable, CHECK, root], capture_output=True, text=True)
    return done.returncode, done.stdout + done.stderr


def write(root, path, text):
    os.makedirs(os.path.dirname(os.path.join(root, path)) or root, exist_ok=True)
    with open(os.path.join(root, path), 'w', encoding='utf-8') as f:
        f.write(text)


def expect(condition, message, output):
    if not condition:
        print(f'FAIL: {message}\n--- checker output ---\n{output}')
        sys.exit(1)


def main():
    root = tempfile.mkdtemp(prefix='check-links-')
    try:
        write(root, 'README.md',
              '# Project\n\n'
              'Read [the guide](docs/guide.md#the-vrl-render-command) first.\n'
              'Then [the missing page](docs/missing.md).\n')
        write(root, 'docs/guide.md',
              '# Guide\n\n## The `vrl render` command\n\nText.\n')
        code, out = run(root)
        expect(code == 1, 'a broken link must exit 1', out)
        expect('README.md:4: docs/missing.md' in out, 'the broken link is named as file:line: target', out)
        expect('docs/guide.md' not in out.replace('docs/missing.md', ''), 'the good link is not reported', out)

        write(root, 'docs/missing.md', '# Now here\n')
        code, out = run(root)
        expect(code == 0, 'once the target exists the check passes', out)
        expect('checked 2 links in 3 files' in out, 'it reports what it checked', out)

        # A link to a heading that does not exist fails; one to a repeated heading's second slug passes.
        write(root, 'docs/guide.md',
              '# Guide\n\n## The `vrl render` command\n\n## Notes\n\n## Notes\n\n'
              '[back](../README.md#project) [second notes](#notes-1) [gone](#no-such-heading)\n')
        code, out = run(root)
        expect(code == 1 and 'docs/guide.md:9: #no-such-heading' in out, 'a missing anchor fails', out)
        expect('#notes-1' not in out and '#project' not in out, 'existing anchors pass', out)

        # Links in fenced code and code spans, web links and mailto are not checked.
        write(root, 'docs/guide.md',
              '# Guide\n\n## The `vrl render` command\n\n## Parts: (a)-(d), 2×2!\n\n'
              '```md\n[in a fence](nowhere.md)\n```\n\n'
              '`[in a span](nowhere.md)` [web](https://example.com/x.md) [mail](mailto:a@b.c)\n'
              '![picture](img/p.png "title") [here](#parts-a-d-22)\n')
        write(root, 'docs/img/p.png', '')
        code, out = run(root)
        expect(code == 0, 'code, web links and slugs with punctuation pass', out)
    finally:
        shutil.rmtree(root)
    print('check_links: fails on a broken link or anchor, passes once mended')
    return 0


if __name__ == '__main__':
    sys.exit(main())
