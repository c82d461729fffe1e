#!/usr/bin/env python3
"""The layering rules of the source tree (docs/architecture.md), checked on every
#include "..." of every C++ file under the given root:

  1. render/ includes nothing from proto/, service/, server/, worker/ or client/
     (the renderer knows nothing of gRPC or of the programs);
  2. proto/ and service/common/ include nothing from render/;
  3. server/ and worker/ do not include each other;
  4. render/core/ includes nothing outside render/core/;
  5. util/ includes nothing outside util/ (leaf helpers);
  6. no cycle between files;
  7. outside render/scene_io/mitsuba/ (and the tests and fuzzers that probe it),
     only its public header, mitsuba_parser.h, is included;
  8. render/'s floor plan runs one way down (RENDER_FLOORS): a folder includes
     its own files and folders on lower floors only, never a folder on its own
     floor or above. So scene/ does not include scene_io/ (they share a floor:
     the parser writes descriptions, the scene builds from them), materials/ does
     not include scene/, vrl/ does not include lightcuts/; inside lightcuts/ the
     rooms run tree/ -> bounds/ -> cuts/. A render/ folder missing from
     RENDER_FLOORS is itself a violation, so a new one is placed on purpose.

Project includes are written from the repository root ("render/core/rgb.h");
generated API headers ("vrl/v1/vrl.pb.h", "grpc/health/v1/health.pb.h") count
as proto/. Exits 0 when the tree keeps every rule, 1 with one line per
violation (file:line: rule, include) otherwise, 2 for bad usage.
"""
import argparse
import os
import re
import sys

SOURCE_EXTENSIONS = ('.h', '.hpp', '.cpp', '.cc')
SKIP_DIRS = {'.git', 'build', 'docs'}
MITSUBA_PRIVATE = 'render/scene_io/mitsuba/'
MITSUBA_PUBLIC = 'render/scene_io/mitsuba/mitsuba_parser.h'
# render/'s folders, lowest floor first; the files directly under render/
# (renderer.h, the front door) stand on top. Folders on one floor are siblings
# that must not include each other.
RENDER_FLOORS = [
    ['core'],
    ['description'],
    ['media', 'materials', 'lights', 'shapes', 'image'],
    ['scene', 'scene_io'],
    ['vrl'],
    ['lightcuts/tree'],
    ['lightcuts/bounds'],
    ['lightcuts/cuts'],
    ['integrators'],
]
FRONT_DOOR = '(front door)'
INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')


def part_of(path):
    """The part an include path or file path belongs to ('render/core', 'proto', ...)."""
    if path.startswith('vrl/v1/') or path.startswith('grpc/health/'):
        return 'proto'
    top = path.split('/')[0]
    if top == 'render' and path.startswith('render/core/'):
        return 'render/core'
    if top == 'service' and path.startswith('service/common/'):
        return 'service/common'
    return top


def in_render(part):
    return part in ('render', 'render/core')


def render_room(path):
    """The render/ folder a file or include path belongs to ('scene', 'lightcuts/cuts',
    FRONT_DOOR for files directly under render/), or None outside render/."""
    if not path.startswith('render/'):
        return None
    parts = path.split('/')[1:-1]
    if not parts:
        return FRONT_DOOR
    if parts[0] == 'lightcuts' and len(parts) > 1:
        return 'lightcuts/' + parts[1]
    return parts[0]


def floor_of(room):
    if room == FRONT_DOOR:
        return len(RENDER_FLOORS)
    for number, rooms in enumerate(RENDER_FLOORS):
        if room in rooms:
            return number
    return None


def floor_violation(source, included):
    """Rule 8 for a file `source` including `included`, or None."""
    source_room, included_room = render_room(source), render_room(included)
    if source_room is None or included_room is None or source_room == included_room:
        return None
    for room in (source_room, included_room):
        if floor_of(room) is None:
            return 'render/%s/ is on no floor of the render floor plan (add it to RENDER_FLOORS)' % room
    source_floor, included_floor = floor_of(source_room), floor_of(included_room)
    if included_floor < source_floor:
        return None
    where = 'on its own floor' if included_floor == source_floor else 'above it'
    return 'render/%s/ must not include render/%s/ (%s: the render floor plan runs one way down)' % (
        source_room, included_room, where)


def violation(source_part, include_part):
    """The rule a source in `source_part` breaks by including `include_part`, or None."""
    if in_render(source_part) and include_part in ('proto', 'service', 'service/common', 'server', 'worker', 'client'):
        return 'render/ must not include ' + include_part + '/'
    if source_part in ('proto', 'service/common') and in_render(include_part):
        return source_part + '/ must not include render/'
    if (source_part, include_part) in (('server', 'worker'), ('worker', 'server')):
        return 'server/ and worker/ must not include each other'
    if source_part == 'render/core' and include_part != 'render/core':
        return 'render/core/ must include nothing outside render/core/'
    if source_part == 'util' and include_part != 'util':
        return 'util/ must include nothing outside util/'
    return None


def collect(root):
    files = {}
    for directory, subdirs, names in os.walk(root):
        rel_dir = os.path.relpath(directory, root)
        if rel_dir == '.':
            subdirs[:] = [d for d in subdirs if d not in SKIP_DIRS and not d.startswith('build')]
        for name in names:
            if name.endswith(SOURCE_EXTENSIONS):
                rel = os.path.normpath(os.path.join(rel_dir, name)).replace(os.sep, '/')
                includes = []
                with open(os.path.join(directory, name), encoding='utf-8', errors='replace') as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if m:
                            includes.append((number, m.group(1)))
                files[rel] = includes
    return files


def find_cycles(graph):
    """Strongly connected components with more than one file, or a file including itself (Tarjan)."""
    index, low, on_stack, stack, result = {}, {}, set(), [], []
    counter = [0]

    def visit(start):
        work = [(start, iter(sorted(graph.get(start, ()))))]
        index[start] = low[start] = counter[0]
        counter[0] += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            advanced = False
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter[0]
                    counter[0] += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.get(child, ())))))
                    advanced = True
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            if advanced:
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1 or node in graph.get(node, ()):
                    result.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return result


def check(root):
    files = collect(root)
    problems = []
    graph = {}
    for source, includes in sorted(files.items()):
        source_part = part_of(source)
        for number, included in includes:
            problem = violation(source_part, part_of(included)) or floor_violation(source, included)
            if (not problem and included.startswith(MITSUBA_PRIVATE) and included != MITSUBA_PUBLIC
                    and not source.startswith((MITSUBA_PRIVATE, 'tests/', 'fuzz/'))):
                problem = 'only ' + MITSUBA_PUBLIC + ' of render/scene_io/mitsuba/ is public'
            if problem:
                problems.append('%s:%d: %s (#include "%s")' % (source, number, problem, included))
            if included in files:
                graph.setdefault(source, set()).add(included)
    for component in find_cycles(graph):
        problems.append('include cycle between files: ' + ' -> '.join(component))
    return files, problems


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('root', nargs='?', default=os.path.join(os.path.dirname(__file__), '..', '..'),
                        help='the source tree (default: this repository)')
    args = parser.parse_args()
    if not os.path.isdir(args.root):
        print('check_layering: no such folder: ' + args.root, file=sys.stderr)
        return 2
    files, problems = check(args.root)
    for problem in problems:
        print(problem)
    includes = sum(len(i) for i in files.values())
    print('layering: %d files, %d includes, %d violations' % (len(files), includes, len(problems)))
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main())
