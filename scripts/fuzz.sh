#!/usr/bin/env bash
# The long fuzz run: every mesh reader and the config parser, 1 M mutated inputs each by default
# (ROAR_FUZZ_EXECS overrides, ROAR_FUZZ_SEED picks another random sequence), in release mode.
# Seeds are cut from the shared meshes at run time (ROAR_TEST_DATA, default ../shared/data/meshes
# beside the checkout). A panicking input is kept under target/tmp/fuzz-crashes/.
set -euo pipefail
cd "$(dirname "$0")/.."
export ROAR_TEST_DATA="${ROAR_TEST_DATA:-$(cd ../shared/data/meshes && pwd)}"
export ROAR_FUZZ_EXECS="${ROAR_FUZZ_EXECS:-1000000}"
cargo test --release -p roar-io --test fuzz_readers -- --nocapture
cargo test --release -p roar-cli --test fuzz_config -- --nocapture
