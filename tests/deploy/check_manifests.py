#!/usr/bin/env python3
"""Static checks for the deployment files under deploy/.

Usage: check_manifests.py REPO_ROOT

Parses every deploy/**/*.yaml|*.yml and deploy/Dockerfile and checks:
  * every YAML file parses (yaml.safe_load_all);
  * Kubernetes documents (under deploy/k8s/) have apiVersion, kind and
    metadata.name; Deployments' containers have gRPC readiness and liveness
    probes and resources.requests; the worker Deployment sets replicas;
    container args are strings; selectors match template labels; Services
    select some Deployment; referenced Secrets/PVCs are defined;
  * the token reaches every container from a Secret (secret volume or
    secretKeyRef), never as a literal value;
  * kustomization resources exist and do not include a Secret;
  * the compose file has coordinator and worker services, the token comes
    from a compose secret, both have healthchecks and the worker waits for a
    healthy coordinator;
  * the Dockerfile has at least two FROM lines, the first on Debian 12
    (debian:12, localhost/debian:12 or an ARG defaulting to one); its build
    stage copies, before compiling, the top-level CMakeLists.txt and every
    directory it adds with tests off, and never the whole context (so editing
    deploy/ does not recompile); its last stage installs the package list
    derived from ldd (no hand-listed lib* packages) and checks ldd;
  * .dockerignore exists and excludes local state (vrl-state), tokens, build
    trees and .git.

Prints "checked N files, M documents"; exits 0 on success, 1 on failure.
Needs only the standard library and PyYAML (python3-yaml).
"""

import re
import shlex
import sys
from pathlib import Path

try:
    import yaml
except ImportError:  # pragma: no cover
    print("check_manifests: PyYAML missing (apt install python3-yaml)", file=sys.stderr)
    sys.exit(1)

COMPOSE_NAMES = {"compose.yaml", "compose.yml", "docker-compose.yaml", "docker-compose.yml"}
KUSTOMIZATION_NAMES = {"kustomization.yaml", "kustomization.yml", "Kustomization"}
TOKEN_FLAG = "--token-file"


class Checker:
    def __init__(self, root: Path):
        self.root = root
        self.deploy = root / "deploy"
        self.errors = []
        self.files = 0
        self.documents = 0
        # (path, doc) of every Kubernetes object under deploy/k8s
        self.k8s = []
        # file being checked, named if an unexpected structure crashes a check
        self.current = None

    # ------------------------------------------------------------- helpers
    def rel(self, path: Path) -> str:
        try:
            return str(path.relative_to(self.root))
        except ValueError:
            return str(path)

    def fail(self, path: Path, msg: str, doc=None):
        where = self.rel(path)
        if isinstance(doc, dict):
            kind = doc.get("kind", "?")
            name = (doc.get("metadata") or {}).get("name", "?") if isinstance(doc.get("metadata"), dict) else "?"
            where += f" [{kind}/{name}]"
        self.errors.append(f"{where}: {msg}")

    # ---------------------------------------------------------------- main
    def run(self) -> int:
        if not self.deploy.is_dir():
            self.errors.append(f"{self.rel(self.deploy)}: directory missing")
            return self.finish()

        yaml_files = sorted(p for p in self.deploy.rglob("*")
                            if p.is_file() and (p.suffix in (".yaml", ".yml") or p.name == "Kustomization"))
        if not yaml_files:
            self.errors.append(f"{self.rel(self.deploy)}: no *.yaml / *.yml files found")

        parsed = {}
        for path in yaml_files:
            self.files += 1
            try:
                with open(path, encoding="utf-8") as f:
                    docs = [d for d in yaml.safe_load_all(f) if d is not None]
            except yaml.YAMLError as e:
                self.fail(path, f"YAML parse error: {e}".replace("\n", " "))
                continue
            except (OSError, UnicodeDecodeError) as e:
                self.fail(path, f"cannot read: {e}")
                continue
            self.documents += len(docs)
            parsed[path] = docs

        k8s_dir = self.deploy / "k8s"
        compose_files = []
        kustomizations = []
        for path, docs in parsed.items():
            if path.name in COMPOSE_NAMES:
                compose_files.append((path, docs))
            elif path.name in KUSTOMIZATION_NAMES:
                kustomizations.append((path, docs))
            elif k8s_dir in path.parents:
                for doc in docs:
                    self.check_k8s_object(path, doc)

        self.check_k8s_cross_refs()
        for path, docs in kustomizations:
            self.check_kustomization(path, docs)
        if not compose_files:
            self.errors.append(f"{self.rel(self.deploy)}: no compose.yaml found")
        for path, docs in compose_files:
            self.check_compose(path, docs)

        self.check_dockerfile(self.deploy / "Dockerfile")
        self.check_dockerignore()
        return self.finish()

    def finish(self) -> int:
        for e in self.errors:
            print(f"FAIL: {e}", file=sys.stderr)
        print(f"checked {self.files} files, {self.documents} documents")
        if self.errors:
            print(f"check_manifests: {len(self.errors)} problem(s)", file=sys.stderr)
            return 1
        return 0

    # ---------------------------------------------------------- kubernetes
    def check_k8s_object(self, path: Path, doc):
        self.current = path
        if not isinstance(doc, dict):
            self.fail(path, f"document is a {type(doc).__name__}, expected a mapping")
            return
        ok = True
        for key in ("apiVersion", "kind"):
            if not isinstance(doc.get(key), str) or not doc.get(key):
                self.fail(path, f"missing {key}", doc)
                ok = False
        meta = doc.get("metadata")
        if not isinstance(meta, dict) or not isinstance(meta.get("name"), str) or not meta.get("name"):
            self.fail(path, "missing metadata.name", doc)
            ok = False
        if not ok:
            return
        self.k8s.append((path, doc))
        if doc["kind"] == "Deployment":
            self.check_deployment(path, doc)
        elif doc["kind"] == "Service":
            ports = (doc.get("spec") or {}).get("ports")
            if not ports:
                self.fail(path, "Service has no spec.ports", doc)

    def check_deployment(self, path: Path, doc):
        spec = doc.get("spec")
        if not isinstance(spec, dict):
            self.fail(path, "Deployment has no spec", doc)
            return
        name = doc["metadata"]["name"]
        labels = (doc["metadata"].get("labels") or {})
        is_worker = "worker" in name or labels.get("app.kubernetes.io/component") == "worker"
        if is_worker and not isinstance(spec.get("replicas"), int):
            self.fail(path, "worker Deployment must set spec.replicas (the scaling knob)", doc)

        template = spec.get("template") or {}
        tlabels = ((template.get("metadata") or {}).get("labels") or {})
        match = ((spec.get("selector") or {}).get("matchLabels") or {})
        if not match:
            self.fail(path, "spec.selector.matchLabels missing", doc)
        elif any(tlabels.get(k) != v for k, v in match.items()):
            self.fail(path, f"selector {match} does not match template labels {tlabels}", doc)

        pod = template.get("spec")
        if not isinstance(pod, dict):
            self.fail(path, "spec.template.spec missing", doc)
            return
        containers = pod.get("containers")
        if not isinstance(containers, list) or not containers:
            self.fail(path, "no containers", doc)
            return

        volumes = {v.get("name"): v for v in (pod.get("volumes") or []) if isinstance(v, dict)}
        for c in containers:
            if not isinstance(c, dict):
                self.fail(path, "container entry is not a mapping", doc)
                continue
            cname = c.get("name", "?")
            if not c.get("image"):
                self.fail(path, f"container {cname}: no image", doc)
            for probe in ("readinessProbe", "livenessProbe"):
                p = c.get(probe)
                if not isinstance(p, dict):
                    self.fail(path, f"container {cname}: missing {probe}", doc)
                elif not isinstance(p.get("grpc"), dict) or not isinstance(p["grpc"].get("port"), int):
                    self.fail(path, f"container {cname}: {probe} must be a grpc probe with an integer port", doc)
            requests = ((c.get("resources") or {}).get("requests"))
            if not isinstance(requests, dict) or not requests.get("cpu") or not requests.get("memory"):
                self.fail(path, f"container {cname}: resources.requests (cpu and memory) missing", doc)
            for field in ("command", "args"):
                for a in c.get(field) or []:
                    if not isinstance(a, str):
                        self.fail(path, f"container {cname}: {field} entry {a!r} is not a string (quote it)", doc)
            for e in c.get("env") or []:
                if isinstance(e, dict) and "value" in e and not isinstance(e["value"], str):
                    self.fail(path, f"container {cname}: env {e.get('name')} value {e['value']!r} is not a string", doc)
            self.check_k8s_token(path, doc, c, volumes)

    def check_k8s_token(self, path, doc, c, volumes):
        cname = c.get("name", "?")
        sources = 0
        for e in c.get("env") or []:
            if not isinstance(e, dict) or "TOKEN" not in str(e.get("name", "")).upper():
                continue
            if "value" in e:
                self.fail(path, f"container {cname}: env {e['name']} is a literal; use valueFrom.secretKeyRef", doc)
            elif ((e.get("valueFrom") or {}).get("secretKeyRef")):
                sources += 1
            else:
                self.fail(path, f"container {cname}: env {e['name']} does not come from a Secret", doc)
        argv = [str(a) for a in (c.get("command") or []) + (c.get("args") or [])]
        for i, a in enumerate(argv):
            if a.startswith("--token=") or a == "--token":
                self.fail(path, f"container {cname}: token passed literally on the command line", doc)
            if a == TOKEN_FLAG or a.startswith(TOKEN_FLAG + "="):
                tf = a.split("=", 1)[1] if "=" in a else (argv[i + 1] if i + 1 < len(argv) else "")
                if not self.token_file_from_secret(tf, c, volumes):
                    self.fail(path, f"container {cname}: {TOKEN_FLAG} {tf!r} is not inside a volume mounted from a Secret", doc)
                else:
                    sources += 1
        image = str(c.get("image", ""))
        if sources == 0 and "vrl" in image:
            self.fail(path, f"container {cname}: no token configured ({TOKEN_FLAG} from a Secret volume or VRL_TOKEN from secretKeyRef)", doc)

    @staticmethod
    def token_file_from_secret(tf, c, volumes):
        for m in c.get("volumeMounts") or []:
            mp = str(m.get("mountPath", "")).rstrip("/")
            if not mp or not (tf == mp or tf.startswith(mp + "/")):
                continue
            v = volumes.get(m.get("name")) or {}
            if v.get("secret"):
                return True
            projected = (v.get("projected") or {}).get("sources") or []
            if any(isinstance(s, dict) and s.get("secret") for s in projected):
                return True
        return False

    def check_k8s_cross_refs(self):
        self.current = None
        defined = {(d["kind"], d["metadata"]["name"]) for _, d in self.k8s}
        deployments = [d for _, d in self.k8s if d["kind"] == "Deployment"]
        for path, doc in self.k8s:
            self.current = path
            if doc["kind"] == "Service":
                sel = (doc.get("spec") or {}).get("selector") or {}
                if not sel:
                    self.fail(path, "Service has no selector", doc)
                    continue
                hit = False
                for d in deployments:
                    tl = (((d.get("spec") or {}).get("template") or {}).get("metadata") or {}).get("labels") or {}
                    if all(tl.get(k) == v for k, v in sel.items()):
                        hit = True
                if not hit:
                    self.fail(path, f"Service selector {sel} matches no Deployment template", doc)
            if doc["kind"] != "Deployment":
                continue
            pod = ((doc.get("spec") or {}).get("template") or {}).get("spec") or {}
            for v in pod.get("volumes") or []:
                if not isinstance(v, dict):
                    continue
                sec = (v.get("secret") or {}).get("secretName")
                if sec and ("Secret", sec) not in defined:
                    self.fail(path, f"volume {v.get('name')}: Secret {sec!r} not defined under deploy/k8s (documented placeholder expected)", doc)
                claim = (v.get("persistentVolumeClaim") or {}).get("claimName")
                if claim and ("PersistentVolumeClaim", claim) not in defined:
                    self.fail(path, f"volume {v.get('name')}: PersistentVolumeClaim {claim!r} not defined", doc)

    def check_kustomization(self, path: Path, docs):
        self.current = path
        if len(docs) != 1 or not isinstance(docs[0], dict):
            self.fail(path, "kustomization must be a single mapping")
            return
        k = docs[0]
        if k.get("kind", "Kustomization") != "Kustomization":
            self.fail(path, f"kind is {k.get('kind')!r}, expected Kustomization")
        resources = k.get("resources")
        if not isinstance(resources, list) or not resources:
            self.fail(path, "no resources listed")
            return
        for r in resources:
            if not isinstance(r, str):
                self.fail(path, f"resource entry {r!r} is not a string")
                continue
            if "://" in r or r.startswith("github.com/"):
                continue  # remote base: cannot check offline
            target = (path.parent / r)
            if not target.exists():
                self.fail(path, f"resource {r!r} does not exist")
                continue
            if target.is_file():
                try:
                    with open(target, encoding="utf-8") as f:
                        for d in yaml.safe_load_all(f):
                            if isinstance(d, dict) and d.get("kind") == "Secret":
                                self.fail(path, f"resource {r!r} contains a Secret; applying it would overwrite the real token")
                except yaml.YAMLError:
                    pass  # already reported for that file

    # ------------------------------------------------------------- compose
    def check_compose(self, path: Path, docs):
        self.current = path
        if len(docs) != 1 or not isinstance(docs[0], dict):
            self.fail(path, "compose file must be a single mapping")
            return
        comp = docs[0]
        services = comp.get("services")
        if not isinstance(services, dict):
            self.fail(path, "no services")
            return
        for required in ("coordinator", "worker"):
            if required not in services:
                self.fail(path, f"service {required!r} missing")
        top_secrets = comp.get("secrets") or {}
        for name, svc in services.items():
            if not isinstance(svc, dict):
                self.fail(path, f"service {name}: not a mapping")
                continue
            if not svc.get("image") and not svc.get("build"):
                self.fail(path, f"service {name}: neither image nor build")
            test = (svc.get("healthcheck") or {}).get("test")
            if name in ("coordinator", "worker") and not test:
                self.fail(path, f"service {name}: no healthcheck")
            self.check_compose_token(path, name, svc, top_secrets)
        worker = services.get("worker")
        if isinstance(worker, dict):
            dep = worker.get("depends_on")
            cond = None
            if isinstance(dep, dict):
                cond = (dep.get("coordinator") or {}).get("condition")
            if cond != "service_healthy":
                self.fail(path, "service worker: depends_on coordinator must use condition: service_healthy")
            replicas = (worker.get("deploy") or {}).get("replicas")
            if not isinstance(replicas, int):
                self.fail(path, "service worker: deploy.replicas missing")

    def check_compose_token(self, path, name, svc, top_secrets):
        env = svc.get("environment") or {}
        if isinstance(env, list):
            env = dict(e.split("=", 1) if "=" in e else (e, None) for e in env if isinstance(e, str))
        for k, v in env.items():
            if "TOKEN" in str(k).upper() and v not in (None, ""):
                self.fail(path, f"service {name}: {k} set literally in environment; use a compose secret")
        cmd = svc.get("command") or []
        if isinstance(cmd, str):
            cmd = shlex.split(cmd)
        cmd = [str(a) for a in cmd]
        svc_secrets = set()
        for s in svc.get("secrets") or []:
            svc_secrets.add(s if isinstance(s, str) else (s or {}).get("source"))
        token_files = []
        for i, a in enumerate(cmd):
            if a == TOKEN_FLAG and i + 1 < len(cmd):
                token_files.append(cmd[i + 1])
            elif a.startswith(TOKEN_FLAG + "="):
                token_files.append(a.split("=", 1)[1])
        if name in ("coordinator", "worker") and not token_files:
            self.fail(path, f"service {name}: no {TOKEN_FLAG} in command")
        for tf in token_files:
            m = re.fullmatch(r"/run/secrets/([A-Za-z0-9_.-]+)", tf)
            if not m:
                self.fail(path, f"service {name}: {TOKEN_FLAG} {tf!r} is not a compose secret (/run/secrets/NAME)")
                continue
            secret = m.group(1)
            if secret not in svc_secrets:
                self.fail(path, f"service {name}: secret {secret!r} not listed in the service's secrets:")
            if secret not in top_secrets:
                self.fail(path, f"service {name}: secret {secret!r} not defined in top-level secrets:")

    # ---------------------------------------------------------- dockerfile
    def check_dockerfile(self, path: Path):
        self.current = path
        if not path.is_file():
            self.fail(path, "missing")
            return
        self.files += 1
        stages = dockerfile_stages(path.read_text(encoding="utf-8"))
        if len(stages) < 2:
            self.fail(path, f"expected a multi-stage build (>= 2 FROM lines), found {len(stages)}")
            return
        first = stages[0]
        if not re.match(DEBIAN_12, first["base"]):
            self.fail(path, f"first stage must be FROM debian:12 (or localhost/debian:12, or an ARG "
                            f"defaulting to one), found {first['from']!r}")
        self.check_compile_inputs(path, first)
        self.check_runtime_stage(path, stages[-1])

    def check_compile_inputs(self, path: Path, build):
        """The build stage copies exactly what the compile reads before compiling.

        A `COPY . ...` would bring deploy/ (and tests/, docs/) into the compile
        layer, so that editing a manifest recompiles; the named COPYs must then
        cover every directory the top-level CMakeLists.txt adds with tests off.
        """
        copied = set()
        for kind, args in build["instructions"]:
            if kind == "RUN" and re.search(r"\bcmake\b", args):
                break
            if kind in ("COPY", "ADD"):
                words = [w for w in args.split() if not w.startswith("--")]
                if any(w.startswith("--from") for w in args.split()):
                    continue
                for src in words[:-1]:
                    src = src.strip("/") or "."
                    if src in (".", "*"):
                        self.fail(path, f"build stage: `{kind} {args}` before the compile copies the whole "
                                        f"context (deploy/ included): editing deploy/ would recompile")
                    copied.add(src)
        else:
            self.fail(path, "build stage: no `RUN cmake ...` found")
            return
        cmake = self.root / "CMakeLists.txt"
        if not cmake.is_file():
            return
        if "CMakeLists.txt" not in copied:
            self.fail(path, "build stage: CMakeLists.txt is not copied before the compile")
        for sub in compiled_subdirectories(cmake.read_text(encoding="utf-8")):
            if sub not in copied:
                self.fail(path, f"build stage: {sub}/ (add_subdirectory in CMakeLists.txt) is not copied "
                                f"before the compile")

    def check_runtime_stage(self, path: Path, runtime):
        """The image installs the derived package list, not a hand-kept one."""
        runs = [a for k, a in runtime["instructions"] if k == "RUN"]
        installs = [a for a in runs if "apt-get install" in a]
        if not any("runtime-packages" in a for a in installs):
            self.fail(path, "runtime stage: no `apt-get install` of the derived runtime-packages list")
        for a in installs:
            listed = [w for w in a.split() if re.match(r"^lib[a-z0-9.+-]+$", w)]
            if listed:
                self.fail(path, f"runtime stage: hand-listed packages {listed}: install the derived list instead")
        if not any("ldd" in a and "not found" in a for a in runs):
            self.fail(path, "runtime stage: no ldd check for missing shared libraries")

    def check_dockerignore(self):
        path = self.root / ".dockerignore"
        self.current = path
        if not path.is_file():
            self.fail(path, "missing: `COPY` would send local state and tokens into the build")
            return
        self.files += 1
        patterns = [l.strip() for l in path.read_text(encoding="utf-8").splitlines()
                    if l.strip() and not l.strip().startswith("#") and not l.strip().startswith("!")]
        for sample in ("vrl-state", "client/vrl-state", "deploy/token", "vrl.token", "build", ".git"):
            if not any(ignores(p, sample) for p in patterns):
                self.fail(path, f"does not exclude {sample!r}")


DEBIAN_12 = r"^((docker\.io/)?(library/)?|localhost/)debian:12([.\-@]|$)"


def dockerfile_stages(text):
    """Stages of a Dockerfile: [{"from", "base", "name", "instructions": [(KIND, args)]}].

    Continuation lines are joined; ARGs declared before the first FROM are
    substituted into FROM lines with their defaults.
    """
    lines, buf = [], ""
    for raw in text.splitlines():
        s = raw.strip()
        if not buf and (not s or s.startswith("#")):
            continue
        if buf and s.startswith("#"):
            continue
        if s.endswith("\\"):
            buf += s[:-1] + " "
            continue
        lines.append(buf + s)
        buf = ""
    if buf:
        lines.append(buf)
    global_args, stages = {}, []
    for line in lines:
        kind, _, args = line.partition(" ")
        kind = kind.upper()
        if kind == "ARG" and not stages:
            name, _, default = args.strip().partition("=")
            global_args[name] = default.strip().strip('"')
        elif kind == "FROM":
            words = [w for w in args.split() if not w.startswith("--")]
            image = words[0] if words else ""
            base = re.sub(r"\$\{?([A-Za-z_][A-Za-z0-9_]*)\}?", lambda m: global_args.get(m.group(1), ""), image)
            name = words[2] if len(words) >= 3 and words[1].upper() == "AS" else None
            stages.append({"from": image, "base": base, "name": name, "instructions": []})
        elif stages:
            stages[-1]["instructions"].append((kind, args.strip()))
    return stages


def compiled_subdirectories(cmake_text):
    """add_subdirectory() names of a top-level CMakeLists.txt that a build with
    VRL_BUILD_TESTS=OFF (and VRL_FUZZ_ONLY off) configures."""
    subs, skipping = [], []
    for raw in cmake_text.splitlines():
        line = raw.split("#", 1)[0].strip()
        m = re.match(r"if\s*\((.*)\)", line)
        if m:
            skipping.append(bool(re.search(r"\bVRL_(BUILD_TESTS|FUZZ_ONLY)\b", m.group(1))))
            continue
        if re.match(r"endif\s*\(", line):
            if skipping:
                skipping.pop()
            continue
        m = re.match(r"add_subdirectory\s*\(\s*([^\s)]+)", line)
        if m and not any(skipping):
            subs.append(m.group(1))
    return subs


def ignores(pattern, sample):
    """Whether a .dockerignore pattern excludes the path `sample` (Go filepath.Match
    with `**`, as Docker and buildah read it; a directory excludes its contents)."""
    pattern = pattern.strip("/")
    regex = ""
    i = 0
    while i < len(pattern):
        if pattern.startswith("**/", i):
            regex += "(.*/)?"
            i += 3
        elif pattern.startswith("**", i):
            regex += ".*"
            i += 2
        elif pattern[i] == "*":
            regex += "[^/]*"
            i += 1
        elif pattern[i] == "?":
            regex += "[^/]"
            i += 1
        else:
            regex += re.escape(pattern[i])
            i += 1
    return re.fullmatch(regex + "(/.*)?", sample) is not None


def main(argv):
    if len(argv) != 2:
        print("usage: check_manifests.py REPO_ROOT", file=sys.stderr)
        return 1
    root = Path(argv[1]).resolve()
    checker = Checker(root)
    try:
        return checker.run()
    except Exception as e:  # malformed structure we did not anticipate
        for err in checker.errors:
            print(f"FAIL: {err}", file=sys.stderr)
        where = checker.rel(checker.current) if checker.current else "deploy"
        print(f"FAIL: {where}: unexpected structure ({type(e).__name__}: {e})", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
