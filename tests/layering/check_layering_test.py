#!/usr/bin/env python3
"""The layering check fails on each forbidden include and on a cycle, and passes
on a tree that keeps the rules: a synthetic tree per case, built in a temporary
folder, and the real tree with one forbidden include added to a copy of a file."""
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
CHECK = os.path.join(HERE, 'check_layering.py')
REPO = os.path.normpath(os.path.join(HERE, '..', '..'))


def run(root):
    done = subprocess.run([sys.executable, CHECK, root], capture_output=True, text=True)
    return done.returncode, done.stdout


def tree(files):
    root = tempfile.mkdtemp(prefix='layering-')
    for path, text in files.items():
        os.makedirs(os.path.dirname(os.path.join(root, path)), exist_ok=True)
        with open(os.path.join(root, path), 'w') as f:
            f.write(text)
    return root


CLEAN = {
    'render/core/rgb.h': '#pragma once\n',
    'render/scene/scene.h': '#include "render/core/rgb.h"\n#include "util/hash.h"\n',
    'util/hash.h': '#pragma once\n',
    'service/common/rpc.h': '#include "vrl/v1/vrl.pb.h"\n#include "util/hash.h"\n',
    'service/job/job.h': '#include "render/scene/scene.h"\n#include "service/common/rpc.h"\n',
    'server/coordinator.h': '#include "service/job/job.h"\n',
    'worker/worker.h': '#include "service/job/job.h"\n',
    'client/main.cpp': '#include "server/coordinator.h"\n#include "worker/worker.h"\n',
    'render/scene_io/mitsuba/mitsuba_parser.h': '#include "render/scene_io/mitsuba/xml_values.h"\n',
    'render/scene_io/mitsuba/xml_values.h': '#pragma once\n',
    'render/renderer.h': '#include "render/scene_io/mitsuba/mitsuba_parser.h"\n',
    'tests/render/xml_values_test.cpp': '#include "render/scene_io/mitsuba/xml_values.h"\n',
    'render/description/scene_description.h': '#include "render/core/rgb.h"\n',
    'render/materials/bsdf.h': '#include "render/description/scene_description.h"\n',
    'render/shapes/shape_mesh.h': '#include "render/description/scene_description.h"\n',
    'render/vrl/vrl.h': '#include "render/scene/scene.h"\n#include "render/materials/bsdf.h"\n',
    'render/lightcuts/tree/light_tree.h': '#include "render/vrl/vrl.h"\n',
    'render/lightcuts/bounds/cluster_bound.h': '#include "render/lightcuts/tree/light_tree.h"\n',
    'render/lightcuts/cuts/lightcuts_estimator.h': '#include "render/lightcuts/bounds/cluster_bound.h"\n',
    'render/integrators/transport_integrator.h': '#include "render/lightcuts/cuts/lightcuts_estimator.h"\n',
}

BROKEN = [
    ('render/scene/scene.h', '#include "service/common/rpc.h"\n', 'render/ must not include service/common/'),
    ('render/scene/scene.h', '#include "vrl/v1/vrl.pb.h"\n', 'render/ must not include proto/'),
    ('render/scene/scene.h', '#include "client/main.cpp"\n', 'render/ must not include client/'),
    ('service/common/rpc.h', '#include "render/scene/scene.h"\n', 'service/common/ must not include render/'),
    ('proto/api.h', '#include "render/core/rgb.h"\n', 'proto/ must not include render/'),
    ('server/coordinator.h', '#include "worker/worker.h"\n', 'server/ and worker/ must not include each other'),
    ('worker/worker.h', '#include "server/coordinator.h"\n', 'server/ and worker/ must not include each other'),
    ('render/core/rgb.h', '#include "render/scene/scene.h"\n', 'render/core/ must include nothing outside'),
    ('util/hash.h', '#include "render/core/rgb.h"\n', 'util/ must include nothing outside util/'),
    ('render/scene/a.h', '#include "render/scene/b.h"\n', 'include cycle'),
    ('render/renderer.h', '#include "render/scene_io/mitsuba/xml_values.h"\n', 'only render/scene_io/mitsuba/mitsuba_parser.h'),
    # The render floor plan (rule 8): the named back-arrows, a sideways one, an unplaced folder.
    ('render/scene/scene.h', '#include "render/scene_io/mitsuba/mitsuba_parser.h"\n',
     'render/scene/ must not include render/scene_io/'),
    ('render/materials/bsdf.h', '#include "render/scene/scene.h"\n', 'render/materials/ must not include render/scene/'),
    ('render/vrl/vrl.h', '#include "render/lightcuts/tree/light_tree.h"\n', 'render/vrl/ must not include render/lightcuts/tree/'),
    ('render/lightcuts/tree/light_tree.h', '#include "render/lightcuts/cuts/lightcuts_estimator.h"\n',
     'render/lightcuts/tree/ must not include render/lightcuts/cuts/'),
    ('render/core/rgb.h', '#include "render/renderer.h"\n', 'render/core/ must include nothing outside'),
    ('render/integrators/transport_integrator.h', '#include "render/renderer.h"\n',
     'render/integrators/ must not include render/(front door)/'),
    ('render/shapes/shape_mesh.h', '#include "render/materials/bsdf.h"\n', 'render/shapes/ must not include render/materials/ (on its own floor'),
    ('render/gadgets/gadget.h', '#include "render/core/rgb.h"\n', 'render/gadgets/ is on no floor'),
]


def main():
    failures = []
    root = tree(CLEAN)
    code, out = run(root)
    if code != 0:
        failures.append('clean tree refused:\n' + out)
    shutil.rmtree(root)
    for path, line, expected in BROKEN:
        files = dict(CLEAN)
        files[path] = files.get(path, '') + line
        if expected == 'include cycle':
            files['render/scene/b.h'] = '#include "render/scene/a.h"\n'
        root = tree(files)
        code, out = run(root)
        shutil.rmtree(root)
        if code != 1 or expected not in out:
            failures.append('%s + %s: expected exit 1 and "%s", got %d:\n%s' % (path, line.strip(), expected, code, out))
        else:
            print('refused as expected: %s + %s -> %s' % (path, line.strip(), out.splitlines()[0]))
    # The real tree, and a copy of it with renderer.h including the gRPC plumbing.
    code, out = run(REPO)
    if code != 0:
        failures.append('the repository breaks its layering:\n' + out)
    copy = tempfile.mkdtemp(prefix='layering-repo-')
    for part in ('render', 'service', 'server', 'worker', 'client', 'util', 'proto'):
        shutil.copytree(os.path.join(REPO, part), os.path.join(copy, part))
    with open(os.path.join(copy, 'render', 'renderer.h'), 'a') as f:
        f.write('#include "service/common/rpc_common.h"\n')
    code, out = run(copy)
    shutil.rmtree(copy)
    if code != 1 or 'render/renderer.h' not in out:
        failures.append('a forbidden include in a copy of the repository was not caught:\n' + out)
    else:
        print('copy of the repository with a forbidden include: ' + out.splitlines()[0])
    for failure in failures:
        print('FAIL: ' + failure)
    print('%d passed, %d failed' % (len(BROKEN) + 3 - len(failures), len(failures)))
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
