#!/usr/bin/env bash
# The cluster section of the README, as far as a machine without a cluster
# allows: every manifest validated against the Kubernetes schemas (offline,
# the `kubernetes-validate` Python package, strict), then each workload's
# container run with Docker exactly as its manifest says — the Deployment's
# service answering /healthz, every index of the Indexed compare Job on the
# sweep given as its ConfigMap, and the merge Job over their volume.
#
#   docker/k8s/check.sh IMAGE [SWEEP.toml]     (default sweep: docker/sweep.toml)
set -euo pipefail
cd "$(dirname "$0")"
image="${1:?usage: check.sh IMAGE [SWEEP.toml]}"
sweep="$(realpath "${2:-../sweep.toml}")"

# 1. The schemas.
venv="${KUBERNETES_VALIDATE_VENV:-$HOME/.cache/continuum-kubernetes-validate}"
[ -x "$venv/bin/kubernetes-validate" ] || {
    python3 -m venv "$venv"
    "$venv/bin/pip" install -q kubernetes-validate
}
"$venv/bin/kubernetes-validate" --strict --quiet ./*.yaml
echo "k8s: every manifest valid (kubernetes-validate --strict)"

# The container of a workload (kind/name) from a manifest, as JSON.
container() {
    "$venv/bin/python" - "$@" <<'PY'
import json, sys, yaml
path, kind, name = sys.argv[1:4]
for doc in yaml.safe_load_all(open(path)):
    if doc and doc["kind"] == kind and doc["metadata"]["name"] == name:
        spec = doc["spec"]
        print(json.dumps({"container": spec["template"]["spec"]["containers"][0],
                          "completions": spec.get("completions", 1)}))
        break
else:
    sys.exit(f"{path}: no {kind} {name}")
PY
}
# A JSON list field of a container, one item per line.
field() { "$venv/bin/python" -c 'import json,sys; [print(a) for a in json.load(sys.stdin)["container"].get(sys.argv[1], [])]' "$1"; }

cleanup() { [ -n "${cid:-}" ] && docker rm -f "$cid" >/dev/null 2>&1 || true; }
trap cleanup EXIT

# 2. The Deployment's container, with its args, answers its probes' /healthz.
spec=$(container service.yaml Deployment continuum)
mapfile -t args < <(field args <<<"$spec")
cid=$(docker run -d -p 127.0.0.1::8080 "$image" "${args[@]}")
port=$(docker port "$cid" 8080/tcp | head -n 1 | sed 's/.*://')
for _ in $(seq 60); do curl -sf "http://127.0.0.1:$port/healthz" >/dev/null && break; sleep 1; done
curl -sf "http://127.0.0.1:$port/healthz" >/dev/null || { docker logs "$cid"; echo "k8s: the Deployment's container is not healthy"; exit 1; }
# The log is standard error (standard output has the URL line): JSON objects only.
logs=$(docker logs "$cid" 2>&1 >/dev/null)
[ -n "$logs" ] && ! grep -qv '^{' <<<"$logs" || { echo "$logs"; echo "k8s: --log-format json did not log JSON lines"; exit 1; }
docker rm -f "$cid" >/dev/null; cid=""
echo "k8s: the Deployment's container serves /healthz with its manifest's args"

# 3. Every index of the Indexed Job into one results volume, then the merge Job.
results=$(mktemp -d); chmod 0777 "$results"
spec=$(container compare-job.yaml Job continuum-compare)
completions=$("$venv/bin/python" -c 'import json,sys; print(json.load(sys.stdin)["completions"])' <<<"$spec")
mapfile -t args < <(field args <<<"$spec")
for ((i = 0; i < completions; i++)); do
    docker run --rm -v "$results:/results" -v "$sweep:/sweep/sweep.toml:ro" "$image" \
        "${args[@]//\$(JOB_COMPLETION_INDEX)/$i}" >/dev/null
done
spec=$(container merge-job.yaml Job continuum-merge)
mapfile -t command < <(field command <<<"$spec")
docker run --rm -v "$results:/results" --entrypoint "${command[0]}" "$image" "${command[@]:1}" >/dev/null
for f in results.json results.csv report.html; do
    [ -s "$results/merged/$f" ] || { echo "k8s: the merge Job wrote no $f"; exit 1; }
done
echo "k8s: $completions compare shards and their merge wrote $results/merged/report.html"
