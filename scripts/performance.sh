#!/usr/bin/env bash
# Renews docs/performance.md from one bench run: every criterion bench of `benches/step.rs`, then
# (unless --no-study) the work–precision study, then `examples/performance.rs`, which writes the
# tables from target/criterion and output/work_precision/summary.md.
# Usage: scripts/performance.sh [--no-study] [CRITERION FILTER...]
set -euo pipefail
cd "$(dirname "$0")/.."
study=yes
if [ "${1:-}" = --no-study ]; then
    study=no
    shift
fi
# One run: results of earlier runs must not mix into the tables.
rm -rf target/criterion
cargo bench --bench step -- "$@"
summary=()
if [ "$study" = yes ]; then
    cargo run --release --example work_precision
    summary=(output/work_precision/summary.md)
fi
cargo run --example performance -- target/criterion docs/performance.md "${summary[@]}"
