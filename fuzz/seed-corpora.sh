#!/usr/bin/env bash
# Writes the fuzz targets' seed corpora to fuzz/corpus/TARGET/ (git-ignored): NIST's I++ DME test files
# (shared/reference/ippdme-nist-1.4 beside the checkout) for codec and response, a line of each control API
# request for control_request, the committed config/*.toml and config/parts/*.toml for the two loaders. The
# seeds come from tests/fuzz_targets.rs, which the stable mutation run starts from too.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --test fuzz_targets write_seed_corpora -- --ignored --exact
for dir in fuzz/corpus/*/; do
    echo "$dir: $(ls "$dir" | wc -l) files"
done
