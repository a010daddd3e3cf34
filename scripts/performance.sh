#!/usr/bin/env bash
# Renews docs/performance.md from one bench run: every criterion bench of `benches/step.rs`, then
# (unless --no-study) the peers' tests with BDF (which the default build leaves out) and the
# work–precision study and the field's against the method of lines, then
# `examples/performance.rs`, which writes the tables from target/criterion and the two summaries.
# Usage: scripts/performance.sh [--no-study]
set -euo pipefail
cd "$(dirname "$0")/.."
study=yes
case "${1:-}" in
    "") ;;
    --no-study) study=no ;;
    *) echo "usage: $0 [--no-study]" >&2; exit 2 ;;
esac
criterion="${CARGO_TARGET_DIR:-target}/criterion"
# One run of every bench: results of earlier runs must not mix into the tables.
rm -rf "$criterion"
cargo bench --bench step
if [ "$study" = yes ]; then
    # With the BDF peer, which the default build leaves out: its tests first.
    cargo test --features scenes/bdf --test suite peers
    cargo run --release --example work_precision --features scenes/bdf
    cargo run --release --example field_work_precision
    cargo run --example performance -- "$criterion" docs/performance.md \
        output/work_precision/summary.md output/field_work_precision/summary.md
else
    cargo run --example performance -- "$criterion" docs/performance.md
fi
