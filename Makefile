# One command per developer task; CI runs the same test command (.ci/run).
.PHONY: build dev lint test test-fast bench bench-engine docs wheel

build:  ## install grainlab (release build of the Rust engine)
	pip install .

dev:  ## editable install: Python edits are live; rerun after Rust edits
	pip install -e .

wheel:  ## the release artifacts in dist/: the abi3 wheel for manylinux2014 (glibc 2.17+, linked by zig; its own cargo folder target/wheel) and the sdist
	CARGO_TARGET_DIR=target/wheel python -m maturin build --release --zig --compatibility manylinux2014 --out dist
	python -m maturin sdist --out dist

# NO_MKDOCS_2_WARNING=1: Material for MkDocs 9.x prints a notice of its own end of life (May 2027)
# on every build; it says nothing of this site, whose warnings all fail the strict build.
docs:  ## the documentation site in site/ (mkdocs build --strict: any warning, a broken link or reference, fails it); installs grainlab and the docs' packages first when they are missing
	@python -c "import grainlab, material, mkdocstrings_handlers.python" 2>/dev/null || pip install -e ".[test]"
	NO_MKDOCS_2_WARNING=1 python -m mkdocs build --strict

lint:  ## formatting and lints, Rust and Python, types (mypy strict, the compiled module's stub), the import-layer contract and the function-length rule (ARCHITECTURE.md)
	cargo fmt --all -- --check
	cargo clippy --release -p grainlab-core -p grainlab-py -- -D warnings
	ruff check python tests benchmarks examples docs/hooks
	python -m mypy python/grainlab
	python -m mypy docs/hooks
	python -m mypy.stubtest grainlab._core
	python -m pytest -q -p no:cacheprovider tests/test_layers.py tests/test_function_length.py

test:  ## the whole suite, as CI runs it
	bash .ci/run

test-fast:  ## the quick local loop: engine tests and pytest without slow physics runs
	cargo test --release -p grainlab-core
	python -m pytest -m "not slow" -q

bench:  ## every speed figure of docs/engine.md, side by side, medians (about 35 minutes on a quiet 2-core machine; the freud comparison needs pip install freud-analysis)
	python benchmarks/throughput.py --repeat 9
	python benchmarks/shared_machine.py --repeat 5
	python benchmarks/throughput_large.py --repeat 3
	python benchmarks/analysis_large.py --repeat 3
	python benchmarks/analysis_vs_freud.py --repeat 3
	python benchmarks/biaxial_default.py --repeat 1
	python benchmarks/consolidation.py

bench-engine:  ## the engine alone (no Python): the throughput case from Rust
	cargo run --release -p grainlab-core --example throughput -- 1
	cargo run --release -p grainlab-core --example throughput -- 2
