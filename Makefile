# skin_control: `make demo` (main job), `make test` (every test suite), `make bench` (figures),
# `make study` (speed/accuracy trade-offs: docs/tradeoffs.md).
# Each target bootstraps what is missing first (scripts/bootstrap: apt, .deps/venv, MuJoCo).
SHELL := /bin/bash
.SHELLFLAGS := -eo pipefail -c
TOP := $(CURDIR)
DEPS := $(TOP)/.deps
ENV := source $(DEPS)/env.sh &&
MSGS_STAMP := $(DEPS)/ros/install/share/skin_msgs/package.xml
MSG_SRCS := $(wildcard skin_msgs/msg/*.msg skin_msgs/srv/*.srv) skin_msgs/CMakeLists.txt skin_msgs/package.xml
# tf2_msgs from third_party/ros2-jazzy-python (scripts/bootstrap, step 6): r2r must generate it once it is there.
MSG_SRCS += $(wildcard $(DEPS)/ros/install/.ros2-jazzy-python.stamp)
CARGO_PROFILE ?= dev

.PHONY: help bootstrap msgs build lint test test-rust test-robot-package test-integration run demo bench performance study campaign clean fuzz test-fuzz

help:
	@echo "make demo   bootstrap, build, run the main job: the intentional_contact scenario (see README.md)"
	@echo "make run SCENE=<name>  run one scenario (skin_sim list), outputs in out/<name>/"
	@echo "make test   bootstrap, build, run every test suite (cargo tests + test/ integration tests)"
	@echo "make fuzz   fuzz skin_core with libFuzzer on stable, FUZZ_SECONDS per target (default 600; docs/fuzzing.md)"
	@echo "make bench  run the benchmarks; figures in out/bench/summary.json"
	@echo "make campaign  randomized scene campaign (200 scenes): out/campaign/summary.json, docs/robustness.md"
	@echo "make performance  docs/performance.md and docs/performance/*.png from the results of make bench"
	@echo "make study  speed/accuracy study (rate, timestep, skin density, inverse damping): out/study/results.json,"
	@echo "            docs/tradeoffs.md and docs/tradeoffs/*.png; STUDY_ARGS=--full for the whole grid (long)"
	@echo "make clean  remove build outputs (keeps .deps; rm -rf .deps for a full reset)"

bootstrap:
	@scripts/bootstrap

# skin_msgs: ament_cmake interface package, built by colcon into .deps/ros/install (C + Python typesupport).
$(MSGS_STAMP): $(MSG_SRCS) | bootstrap
	@echo "[make] colcon build skin_msgs"
	@mkdir -p $(DEPS)/ros
	@$(ENV) cd $(DEPS)/ros && colcon build --base-paths $(TOP)/skin_msgs --merge-install \
	    --build-base build --install-base install --event-handlers console_cohesion- console_stderr- \
	    --cmake-args -DPython3_EXECUTABLE=$(DEPS)/venv/bin/python -DBUILD_TESTING=OFF \
	    > $(DEPS)/ros/colcon.log 2>&1 || { tail -40 $(DEPS)/ros/colcon.log; echo "colcon build of skin_msgs failed; full log: .deps/ros/colcon.log"; exit 1; }
	@# r2r caches its generated bindings by environment only: drop them so changed messages are seen
	@$(ENV) cargo clean --quiet -p r2r_msg_gen -p r2r && cargo clean --quiet --release -p r2r_msg_gen -p r2r
	@touch $@

msgs: bootstrap $(MSGS_STAMP)

build: msgs
	@echo "[make] cargo build (workspace, all targets)"
	@$(ENV) cargo build --workspace --all-targets --quiet

test-rust: build
	@echo "[make] cargo test (workspace)"
	@$(ENV) cargo test --workspace --quiet 2>&1 | tee $(DEPS)/cargo-test.log

test-integration: build
	@echo "[make] integration tests (test/, pytest with rclpy, rosbags, pinocchio, MuJoCo as outside peers)"
	@$(ENV) SKIN_TARGET_DIR=$(TOP)/target/debug python -m pytest -q test

# Formatting (rustfmt.toml) and lints (clippy, every warning an error).
lint: msgs
	@echo "[make] cargo fmt --check, cargo clippy -D warnings"
	@$(ENV) cargo fmt --all --check
	@$(ENV) cargo clippy --workspace --all-targets --quiet -- -D warnings

# The robot package without MuJoCo (scripts/check_robot_package: dependencies and linked libraries).
test-robot-package: build
	@echo "[make] robot package skin_control without MuJoCo"
	@$(ENV) scripts/check_robot_package

test: lint test-rust test-robot-package test-integration test-fuzz
	@echo "[make] all test suites passed"

# Coverage-guided fuzzing of skin_core on the stable toolchain (docs/fuzzing.md); `make test` runs
# each target briefly. Builds into target/fuzz; exits non-zero on a finding.
FUZZ_SECONDS ?= 600
fuzz: bootstrap
	@scripts/fuzz $(FUZZ_SECONDS)

test-fuzz: bootstrap
	@echo "[make] fuzz (20 s per target)"
	@scripts/fuzz 20

# One closed-loop scenario (skin_sim list names them); metrics.json and summary.txt in out/$(SCENE)/.
# The debug profile is fast enough (opt-level 1): 20-90 s scenes run in 1-5 s.
SCENE ?= intentional_contact
run: build
	@$(ENV) target/debug/skin_sim run $(SCENE) --out out/$(SCENE)

demo: build
	@$(ENV) scripts/demo

bench: build
	@$(ENV) scripts/bench

# Cost curves of the control cycle over cells, active cells and joints, from `make bench`'s results
# (out/bench/summary.json, out/bench/stages.json).
performance: bootstrap
	@echo "[make] skin_sim performance"
	@$(ENV) cargo run --quiet -p skin_sim --bin skin_sim -- performance

# The speed/accuracy study: the default grid runs in ~2-3 min on 2 cores with the debug profile
# (opt-level 1, shared with `make test`); only skin_sim is built (no ROS messages needed).
STUDY_ARGS ?=
study: bootstrap
	@echo "[make] skin_sim sweep $(STUDY_ARGS)"
	@$(ENV) cargo run --quiet -p skin_sim --bin skin_sim -- sweep --out out/study --doc docs/tradeoffs.md $(STUDY_ARGS)

# The randomized scene campaign (docs/robustness.md): 200 scenes from seed 1 on every core,
# ~5 min on 2 cores with the debug profile; CAMPAIGN_ARGS="--scenes 400 --seed 2" for others.
CAMPAIGN_ARGS ?=
campaign: bootstrap
	@echo "[make] skin_sim campaign $(CAMPAIGN_ARGS)"
	@$(ENV) cargo run --quiet -p skin_sim --bin skin_sim -- campaign --out out/campaign --doc docs/robustness.md $(CAMPAIGN_ARGS)

clean:
	cargo clean
	rm -rf $(DEPS)/ros out
