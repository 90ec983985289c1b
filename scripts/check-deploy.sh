#!/bin/bash
# Checks deploy/ without a cluster (scripts/slurm-local.sh runs the Slurm
# scripts on a real one):
#   - shellcheck on every deploy script, the Slurm batch scripts and the
#     shell scripts inside the Kubernetes manifests;
#   - the manifests deploy/k8s/submit.sh writes parse as YAML and agree
#     with themselves: completions, the pods' PARTS and the merge's are the
#     one PARTS; CPU request = limit = THREADS, the pods' --threads read from
#     that limit; memory request = limit; restartPolicy Never with the pod
#     failure policy (evictions ignored, exit 2 fails the Job);
#   - the pods' scripts run here under /bin/sh with a real lucent, as the
#     Jobs would run them (a 3-part frame, each index, an index run again,
#     the merge's wait, the merge), the frame compared bitwise with one
#     process;
#   - the Containerfile with hadolint, when it is installed.
#
#   [LUCENT=path/to/lucent] bash scripts/check-deploy.sh
#
# Needs python3 with PyYAML, shellcheck, idiff (scripts/install-deps.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
LUCENT=${LUCENT:-$ROOT/target/debug/lucent}
[ -x "$LUCENT" ] || { echo "${0##*/}: no lucent binary at $LUCENT (build it, or set LUCENT)" >&2; exit 2; }
LUCENT=$(realpath "$LUCENT")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

shellcheck -s bash deploy/memory.sh deploy/slurm/submit.sh deploy/slurm/*.sbatch \
  deploy/k8s/submit.sh scripts/slurm-local.sh scripts/check-deploy.sh

# the manifests, for a 3-part frame of a small Cornell box
sed -e 's/^resolution = .*/resolution = [64, 48]/' -e 's/^spp = .*/spp = 4/' \
  scenes/cornell.toml >"$tmp/cornell.toml"
NAME=box IMAGE=registry.example/lucent:test SCENE=$tmp/cornell.toml OUT=$tmp/frames \
  PARTS=3 THREADS=2 ARGS="--checkpoint 5" deploy/k8s/submit.sh --print >"$tmp/k8s.yaml"
python3 - "$tmp/k8s.yaml" "$tmp" <<'EOF'
import sys, yaml
path, tmp = sys.argv[1], sys.argv[2]
docs = list(yaml.safe_load_all(open(path)))
assert "${" not in open(path).read(), "a template value was left unfilled"
parts, merge = docs
def env(c):
    return {e["name"]: e.get("value", e.get("valueFrom")) for e in c["env"]}
ps, ms = parts["spec"], merge["spec"]
assert ps["completionMode"] == "Indexed" and ps["completions"] == 3, ps
render = ps["template"]["spec"]["containers"][0]
assert env(render)["PARTS"] == "3", env(render)
r = render["resources"]
assert r["requests"] == r["limits"], r
assert r["limits"]["cpu"] == "2", r
t = env(render)["THREADS"]["resourceFieldRef"]
assert t == {"containerName": render["name"], "resource": "limits.cpu", "divisor": "1"}, t
assert '--threads "$THREADS"' in render["args"][0]
pod = ps["template"]["spec"]
assert pod["restartPolicy"] == "Never", pod["restartPolicy"]
rules = ps["podFailurePolicy"]["rules"]
assert {"action": "Ignore", "onPodConditions": [{"type": "DisruptionTarget"}]} in rules, rules
assert any(x["action"] == "FailJob" and x["onExitCodes"]["values"] == [2] for x in rules), rules
mpod = ms["template"]["spec"]
init, mc = mpod["initContainers"][0], mpod["containers"][0]
assert env(init)["PARTS"] == "3" and env(mc)["PARTS"] == "3"
assert env(init)["DIR"] == env(render)["DIR"] == env(mc)["DIR"]
assert mc["resources"]["requests"] == mc["resources"]["limits"]
assert ms["activeDeadlineSeconds"] > 0
claims = {v["persistentVolumeClaim"]["claimName"] for p in (pod, mpod) for v in p["volumes"]}
assert len(claims) == 1, claims
# the pods' scripts and environment, for the run below
for name, c in [("render", render), ("wait", init), ("merge", mc)]:
    open(f"{tmp}/{name}.sh", "w").write(c["args"][0])
    with open(f"{tmp}/{name}.env", "w") as f:
        for k, v in env(c).items():
            if isinstance(v, str):
                f.write(f"export {k}='{v}'\n")
        f.write("export THREADS=2\n")
EOF
for s in render wait merge; do shellcheck -s sh -e SC2154 "$tmp/$s.sh"; done

# the pods, run here: lucent on PATH as in the image
mkdir -p "$tmp/bin"
ln -s "$LUCENT" "$tmp/bin/lucent"
# shellcheck disable=SC1090 # written above
pod() { (. "$tmp/$1.env" && PATH=$tmp/bin:$PATH JOB_COMPLETION_INDEX=${2:-} /bin/sh "$tmp/$1.sh"); }
# the merge's wait, once, before any part: it must not let the merge start
sed 's/sleep 30/exit 3/' "$tmp/wait.sh" >"$tmp/wait-once.sh"
cp "$tmp/wait.env" "$tmp/wait-once.env"
rc=0
pod wait-once >/dev/null || rc=$?
[ "$rc" = 3 ] || { echo "check-deploy: the merge's wait let it start without parts" >&2; exit 1; }
for i in 0 1 2; do pod render "$i"; done
cp "$tmp/frames/box/part-1.exr" "$tmp/part-1.before"
again=$(pod render 1)
if ! grep -q 'exists: nothing to do' <<<"$again" ||
  ! cmp "$tmp/frames/box/part-1.exr" "$tmp/part-1.before"; then
  echo "check-deploy: a k8s index whose part exists rendered it again" >&2
  exit 1
fi
timeout 60 bash -c "$(declare -f pod); tmp=$tmp; pod wait"
pod merge
"$LUCENT" render "$tmp/cornell.toml" --quiet -o "$tmp/single.exr"
idiff -q -fail 0 -warn 0 "$tmp/frames/box.exr" "$tmp/single.exr" >/dev/null || {
  echo "check-deploy: the k8s pods' frame differs from one process" >&2
  exit 1
}
echo "check-deploy: k8s manifests consistent; their pods' 3-part frame bitwise equal to one process"

if command -v hadolint >/dev/null; then
  hadolint deploy/k8s/Containerfile
  echo "check-deploy: Containerfile passes hadolint"
else
  echo "check-deploy: hadolint not installed: Containerfile not linted"
fi
