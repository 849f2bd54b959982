#!/usr/bin/env bash
# The one command run on a lent GPU machine (no Rust there): `facet bench` at its default (GPU)
# sizes, the demo render, the glint counting bench and the GPU tests of the glint and fit
# crates, from binaries staged beside the checkout in .gpu/ (bin/: `facet`, `bench-glint`,
# `test-*` built with `cargo test --release --no-run`; debs/: the Vulkan loader; build_root:
# the checkout's path where they were built). Results and
# one log go to $OUT (default ./device_out). To stage (Vulkan loader packages from Debian's
# libvulkan1 in .gpu/debs): cargo build --release, cargo bench --no-run, cargo test --release
# --no-run -p facet-glint --test glint_flakes --test glint, -p facet-fit --test gpu_fit and
# -p facet-render --test bvh --test integrator (the traversal against obvhs and the integrator's
# tests on the real GPU), copied and stripped into .gpu/bin as test-NAME.
# The working tree that travels is limited to 64 MiB, and these seven binaries take about 65 MB
# stripped: pack them, and only them, into .gpu/bin.tar.gz (about 26 MB), which this script
# unpacks into .gpu/bin:
#   (cd .gpu/bin && tar -czf ../bin.tar.gz facet bench-glint test-*) && rm -rf .gpu/bin
# Usage, from the repository root:
#   bash benches/device_run.sh [MODE]        # MODE: facet bench --mode (default: default)
set -u
mode=${1:-default}
out=${OUT:-device_out}
mkdir -p "$out"
if ! ldconfig -p | grep -q libvulkan; then
    for f in .gpu/debs/*.deb; do dpkg -x "$f" /; done
    ldconfig
fi
nv=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
[[ -f $nv ]] && export VK_DRIVER_FILES=$nv
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/xdg} FACET_REQUIRE_GPU=1 FACET_BACKEND=vulkan
mkdir -p -m 700 "$XDG_RUNTIME_DIR"
# The test binaries find the repository's data through the path they were built in
# (.gpu/build_root holds it).
root=$(cat .gpu/build_root 2>/dev/null)
if [[ -n $root && ! -e $root ]]; then mkdir -p "$(dirname "$root")" && ln -s "$PWD" "$root"; fi
# Where the GPU tests record a skip (CARGO_TARGET_TMPDIR as built).
[[ -n $root ]] && mkdir -p "$root/target/tmp"
b=.gpu/bin
if [[ -f .gpu/bin.tar.gz ]]; then mkdir -p "$b" && tar -xzf .gpu/bin.tar.gz -C "$b"; fi
step() { echo; echo "== $1 ($(date +%T))"; }
{
    command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,power.draw,temperature.gpu,utilization.gpu --format=csv
    echo "cores: $(nproc)"
    # Two runs, two JSONs: a section past its timeout loses only its own figures.
    step "facet bench --mode $mode (trace)"
    timeout 150 $b/facet bench --mode "$mode" --only trace --json "$out/bench_trace.json"
    step "facet bench --mode $mode (GPU sections)"
    timeout 200 $b/facet bench --mode "$mode" --only integrator,dpf,viewer,noise --json "$out/bench_gpu.json"
    step "facet demo"
    timeout 45 $b/facet demo --out /tmp/facet_demo && cp /tmp/facet_demo/demo.png "$out/demo.png"
    step "glint_gpu_count (criterion)"
    timeout 45 $b/bench-glint --bench glint_gpu_count --warm-up-time 1 --measurement-time 3
    step "GPU tests"
    for t in glint_flakes glint gpu_fit bvh integrator; do
        timeout 60 $b/test-$t --test-threads 8 2>&1 | tail -25
    done
    step "facet bench --mode $mode (fit)"
    timeout 60 $b/facet bench --mode "$mode" --only fit --json "$out/bench_fit.json"
    step "done"
} 2>&1 | tee "$out/run.log"
