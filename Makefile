# One command per developer task; CI runs the same test command (.ci/run).
.PHONY: build dev lint test test-fast bench bench-engine

build:  ## install grainlab (release build of the Rust engine)
	pip install .

dev:  ## editable install: Python edits are live; rerun after Rust edits
	pip install -e .

lint:  ## formatting and lints, Rust and Python
	cargo fmt --all -- --check
	cargo clippy --release -p grainlab-core -p grainlab-py -- -D warnings
	ruff check python tests benchmarks examples

test:  ## the whole suite, as CI runs it
	bash .ci/run

test-fast:  ## the quick local loop: engine tests and pytest without slow physics runs
	cargo test --release -p grainlab-core
	python -m pytest -m "not slow" -q

bench:  ## the common throughput case, grainlab vs LAMMPS side by side
	python benchmarks/throughput.py

bench-engine:  ## the engine alone (no Python): the throughput case from Rust
	cargo run --release -p grainlab-core --example throughput -- 1
	cargo run --release -p grainlab-core --example throughput -- 2
