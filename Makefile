# rccx: the commands of the README. Each installs what is missing first (scripts/install-deps).
JOBS ?= 2
DEBUG_DIR := build/debug
RELEASE_DIR := build/release
CMAKE ?= cmake

TSAN_DIR := build/tsan
FUZZ_DIR := build/fuzz
# Seconds all fuzz targets get together in `make test` (scripts/fuzz shares them out).
FUZZ_SECONDS ?= 60

.PHONY: all deps demo demo-view demo-cell test unit-tests fuzz tsan bench bench-cell build-debug build-release format format-check clean

all: build-release

deps:
	@scripts/install-deps

$(DEBUG_DIR)/CMakeCache.txt:
	$(CMAKE) -S . -B $(DEBUG_DIR) -DCMAKE_BUILD_TYPE=Debug -DRCCX_SANITIZE=ON -DRCCX_BUILD_BENCHMARKS=OFF

$(RELEASE_DIR)/CMakeCache.txt:
	$(CMAKE) -S . -B $(RELEASE_DIR) -DCMAKE_BUILD_TYPE=Release -DRCCX_BUILD_TESTS=OFF

build-debug: deps $(DEBUG_DIR)/CMakeCache.txt
	$(CMAKE) --build $(DEBUG_DIR) -j$(JOBS)

build-release: deps $(RELEASE_DIR)/CMakeCache.txt
	$(CMAKE) --build $(RELEASE_DIR) -j$(JOBS)

# The main example: the thesis's window washer in RCCL motion equations, on the simulated Microbo.
demo: build-release
	$(RELEASE_DIR)/examples/04_washer

# The washer at the pace of the wall clock with the view on: open the address it prints; Ctrl-C ends it.
demo-view: build-release
	$(RELEASE_DIR)/examples/04_washer --view

# The two-robot demo on the CVaRL cell: the PUMA presents a circuit board, the Microbo probes it.
demo-cell: build-release
	$(RELEASE_DIR)/examples/10_circuit_board

# The same demo as the thesis ran it, across processes (docs/NETWORK.md): the PUMA and the
# Microbo each in a `rccx serve` process, the program in a third, over DDS on loopback, in real
# time (about two minutes); the same table as demo-cell. scripts/demo-distributed --help.
.PHONY: demo-distributed
demo-distributed: build-release
	scripts/demo-distributed --build $(RELEASE_DIR)

# Debug build (-O1) with AddressSanitizer and UndefinedBehaviorSanitizer, every test, then the
# fuzz targets for FUZZ_SECONDS in all.
test: unit-tests fuzz

unit-tests: build-debug
	cd $(DEBUG_DIR) && ctest --output-on-failure -j$(JOBS)

# libFuzzer targets of every parser of outside input (clang), each on its corpus in fuzz/corpus.
fuzz: deps
	CC=clang CXX=clang++ $(CMAKE) -S . -B $(FUZZ_DIR) -DCMAKE_BUILD_TYPE=Debug -DRCCX_FUZZ=ON \
	  -DCMAKE_C_FLAGS_DEBUG="-g -O1" -DCMAKE_CXX_FLAGS_DEBUG="-g -O1" \
	  -DRCCX_BUILD_TESTS=OFF -DRCCX_BUILD_BENCHMARKS=OFF
	$(CMAKE) --build $(FUZZ_DIR) -j$(JOBS) --target fuzz_targets
	scripts/fuzz --build $(FUZZ_DIR) --seconds $(FUZZ_SECONDS)

# The threaded parts (RTC sessions, a cell's tasks, a serve's and a program's threads) under
# ThreadSanitizer.
tsan: deps
	$(CMAKE) -S . -B $(TSAN_DIR) -DCMAKE_BUILD_TYPE=Debug -DRCCX_TSAN=ON -DRCCX_BUILD_BENCHMARKS=OFF
	$(CMAKE) --build $(TSAN_DIR) -j$(JOBS) --target rccx_rtc_tests rccx_cell_runtime_tests rccx_compat_rtc_tests \
	  rccx_net_threads_tests
	cd $(TSAN_DIR) && TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$(CURDIR)/tests/tsan-suppressions.txt" \
	  ctest -L rtc --output-on-failure -j$(JOBS)

# Release benchmarks against Orocos KDL; JSON under bench-results/. The cell's cycle runs
# apart (bench-cell): its cases take seconds each.
bench: build-release
	@mkdir -p bench-results
	$(RELEASE_DIR)/bench/rccx_bench --benchmark_out=bench-results/kinematics.json \
	  --benchmark_out_format=json --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
	  --benchmark_filter=-BM_CellCycle
	@python3 scripts/bench-report bench-results/kinematics.json

# The Python bindings against the same work in C++ and in PyKDL (python/bench/, docs/PYTHON.md
# "Speed"): the C++ peers (BENCH_PYTHON_CPP, a benchmark filter) and python/bench/run.py in the
# same run, both into bench-results/, then the ratios and goals. The interpreter is the one the
# module was built for (the build's Python3_EXECUTABLE).
BENCH_PYTHON_CPP ?= ^BM_Puma560FK$$|^BM_KdlPuma560FK$$|^BM_MoveToFirstSetpoint/
.PHONY: bench-python
bench-python: deps $(RELEASE_DIR)/CMakeCache.txt
	$(CMAKE) --build $(RELEASE_DIR) -j$(JOBS) --target rccx_bench rccx_python
	@mkdir -p bench-results
	$(RELEASE_DIR)/bench/rccx_bench --benchmark_filter='$(BENCH_PYTHON_CPP)' \
	  --benchmark_out=bench-results/python-cpp.json --benchmark_out_format=json \
	  --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
	py=$$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' $(RELEASE_DIR)/CMakeCache.txt); \
	  test -n "$$py" || { echo "bench-python: $(RELEASE_DIR) has no Python module (RCCX_PYTHON)" >&2; exit 1; }; \
	  PYTHONPATH=$(RELEASE_DIR)/python "$$py" python/bench/run.py --cpp bench-results/python-cpp.json \
	    --out bench-results/python.json && \
	  "$$py" python/bench/report.py bench-results/python.json

# The workcell's cycle (bench/cell_bench.cpp): N robots on one clock, two tasks and one
# thread, ideal servos and the PUMA plant; a fixed number of ticks a case, a few minutes in all.
bench-cell: build-release
	@mkdir -p bench-results
	$(RELEASE_DIR)/bench/rccx_bench --benchmark_filter=BM_CellCycle \
	  --benchmark_out=bench-results/cell.json --benchmark_out_format=json

# The network layer on loopback (docs/NETWORK.md "Benchmark"): Cyclone's ddsperf ping/pong and
# rccx's request round trip, state latency and robots at 1 kHz (bench/net_bench.cpp), one JSON
# document (also bench-results/net.json); about 15 minutes. Builds the benchmark and rccx (its serve).
.PHONY: bench-net
bench-net: deps $(RELEASE_DIR)/CMakeCache.txt
	$(CMAKE) --build $(RELEASE_DIR) -j$(JOBS) --target rccx_net_bench rccx
	@mkdir -p bench-results
	scripts/bench-net --build $(RELEASE_DIR) --out bench-results/net.json

format:
	git ls-files '*.cpp' '*.hpp' | xargs clang-format -i

format-check:
	git ls-files '*.cpp' '*.hpp' | xargs clang-format --dry-run --Werror

clean:
	rm -rf build
