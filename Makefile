# relume — `make demo` bakes the bundled scenes; `make test` installs what it needs and runs
# every test. Everything builds in release mode once (tests share the build).

CARGO    ?= cargo
BAKE     := target/release/relume-bake
PLAYER   := target/release/relume-player
SUDO     := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
APT_PKGS := mesa-vulkan-drivers libvulkan1 libstdc++-12-dev xvfb xauth gdal-bin slurm-wlm munge
PY_PKGS  := pillow numpy openexr tifffile texture2ddecoder rasterio embreex mitsuba pyyaml
export WGPU_BACKEND ?= vulkan
# Mesa warns without a private runtime dir; give it one.
export XDG_RUNTIME_DIR ?= /tmp/relume-xdg-$(shell id -u)

.PHONY: all build demo docs-images test test-slurm deps deps-apt deps-py deps-npm fuzz fmt lint bench bench-grass study ci clean

all: build

build:
	$(CARGO) build --release --locked

## The main job on the bundled default: bake the Cornell box (voxelize → form factors → transport
## → reorder → encode) and Puget Sound (min/max mipmap, at 4K and 2K), compute terrain shadows on
## the CPU, and render headless frames of both with the player (Mesa lavapipe when no GPU).
## A camera south of the Cascades' highest peak looking north over valleys, ridges and the Sound
## (world metres: x east, y up with heights ×3, z south; EYE,TARGET,FOV).
PUGET_CAMERA := 110000,16000,140000,120000,3000,84000,60

demo: build
	@mkdir -p out/demo
	$(BAKE) run pipelines/cornell.ron --out out/demo/cornell
	$(BAKE) run pipelines/puget-sound.ron --out out/demo/puget-sound
	$(BAKE) run pipelines/puget-sound-2k.ron --out out/demo/puget-sound-2k
	$(BAKE) inspect out/demo/cornell
	$(BAKE) export out/demo/cornell patches --out out/demo/cornell-patches.json
	$(BAKE) export out/demo/cornell gltf --sun 20,30 --out out/demo/cornell-lit.glb
	$(BAKE) inspect out/demo/puget-sound
	$(BAKE) shadow pipelines/puget-sound.ron --sun-azimuth 300 --sun-elevation 10 \
	    --out out/demo/puget-sound-shadow.png --shaded out/demo/puget-sound-relief.png
	$(BAKE) softshadow pipelines/puget-sound.ron --sun-azimuth 300 --sun-elevation 3 \
	    --out out/demo/puget-sound-lit.png --shaded out/demo/puget-sound-soft-relief.png
	@mkdir -p -m 0700 $(XDG_RUNTIME_DIR)
	$(PLAYER) out/demo/cornell --headless --exposure 2 --size 640x480 --out out/demo/cornell-frames
	$(PLAYER) out/demo/cornell --headless --exposure 1 --size 640x480 --sun 20,30 --frames 4 \
	    --out out/demo/cornell-sun-frames
	$(PLAYER) out/demo/puget-sound-2k --headless --size 960x540 --sun 265,5 --exposure 2.5 \
	    --camera $(PUGET_CAMERA) --out out/demo/puget-sound-low-sun-frames
	$(PLAYER) out/demo/puget-sound-2k --headless --size 960x540 --sun 200,55 --exposure 1.2 \
	    --camera $(PUGET_CAMERA) --out out/demo/puget-sound-high-sun-frames
	$(PLAYER) out/demo/puget-sound-2k --headless --size 640x480 --sun 300,6 --frames 2 \
	    --camera $(PUGET_CAMERA) --exposure 2.5 --atmosphere fog --out out/demo/puget-sound-frames
	$(PLAYER) out/demo/puget-sound-2k --headless --size 640x480 --sun 300,6 --soft \
	    --camera $(PUGET_CAMERA) --exposure 2.5 --out out/demo/puget-sound-soft-frames
	$(BAKE) theme themes/puget-sound.ron --heightmap pipelines/puget-sound-2k.ron --size 2048 \
	    --out out/demo/puget-sound-themes.png
	@mkdir -p out/demo/freeform
	for s in scenes/freeform/*.ron; do \
	    $(BAKE) freeform render $$s --size 640x480 --quiet \
	        --out out/demo/freeform/$$(basename $$s .ron).png || exit 1; \
	done
	for m in 0.5 1; do \
	    $(BAKE) freeform render scenes/freeform/morph-grid.ron --size 640x480 --morph $$m --quiet \
	        --out out/demo/freeform/morph-grid-$$m.png || exit 1; \
	done
	@echo
	@echo "demo output is in out/demo/:"
	@echo "  cornell/, puget-sound/, puget-sound-2k/        baked directories (relume-bake inspect DIR)"
	@echo "  cornell-patches.json                           the Cornell box's patches"
	@echo "  cornell-lit.glb                                the Cornell box with its baked light and a sun, as glTF (any viewer)"
	@echo "  puget-sound-shadow.png, puget-sound-relief.png hard shadows (CPU, 4K, sun 300°/10°)"
	@echo "  puget-sound-lit.png, puget-sound-soft-relief.png  soft shadows (CPU, 4K, sun 300°/3°)"
	@echo "  cornell-frames/frame_0000.png                  player: the Cornell box lit by its ceiling light"
	@echo "  cornell-sun-frames/frame_000[0-3].png          player: plus a sun turning around it (20°, 110°, 200°, 290°)"
	@echo "  puget-sound-low-sun-frames/frame_0000.png      player: Puget Sound 2K, themes, Hillaire sky, sun 265°/5°"
	@echo "  puget-sound-high-sun-frames/frame_0000.png     player: the same view, sun 200°/55°"
	@echo "  puget-sound-frames/frame_000[0-1].png          player: hard relief shadows, constant-density fog (sun turning)"
	@echo "  puget-sound-soft-frames/frame_0000.png         player: Puget Sound 2K, soft shadows"
	@echo "  puget-sound-themes.png                         the theme albedo at 2048² (relume-bake theme)"
	@echo "  */frames.json                                  adapter and per-pass frame times"
	@echo "  freeform/*.png                                 every bundled freeform scene (CPU multilevel caster),"
	@echo "                                                 morph-grid-0.5.png and -1.png the morph halfway and done"

## Every image the README and docs/ show, regenerated from the code into docs/images/ (player
## frames on the machine's GPU or Mesa lavapipe, terrain images, study plots). Deterministic for
## the same machine and software, except the time axes of the plots. About a minute after the build.
DOCS_OUT := out/docs-images
docs-images: build
	@rm -rf $(DOCS_OUT) && mkdir -p $(DOCS_OUT) docs/images && mkdir -p -m 0700 $(XDG_RUNTIME_DIR)
	$(BAKE) -q run pipelines/cornell.ron --out $(DOCS_OUT)/cornell
	$(BAKE) -q run pipelines/gltf-room.ron --out $(DOCS_OUT)/gltf-room
	$(BAKE) -q run pipelines/puget-sound-2k.ron --out $(DOCS_OUT)/puget-sound-2k
	$(BAKE) -q theme themes/puget-sound.ron --size 480 --out docs/images/themes-puget-sound.png
	$(BAKE) -q run pipelines/furnished-room.ron --out $(DOCS_OUT)/furnished-room
	$(PLAYER) $(DOCS_OUT)/furnished-room --headless -q --size 640x400 --exposure 2.5 \
	    --camera 8.7,1.75,0.4,3.2,0.8,3.0,70 --out $(DOCS_OUT)/furnished-room-frames
	$(PLAYER) $(DOCS_OUT)/cornell --headless -q --size 480x360 --exposure 2 --out $(DOCS_OUT)/cornell-frames
	$(PLAYER) $(DOCS_OUT)/cornell --headless -q --size 480x360 --sun 20,30 --frames 4 --out $(DOCS_OUT)/cornell-sun-frames
	$(PLAYER) $(DOCS_OUT)/gltf-room --headless -q --size 480x360 --exposure 2 \
	    --camera 1.8,1.9,2.6,0,0.3,0,45 --out $(DOCS_OUT)/gltf-room-frames
	$(PLAYER) $(DOCS_OUT)/puget-sound-2k --headless -q --size 480x270 --sun 265,5 --exposure 2.5 \
	    --camera $(PUGET_CAMERA) --out $(DOCS_OUT)/terrain-frames
	$(BAKE) -q shadow pipelines/puget-sound-512.ron --sun-azimuth 300 --sun-elevation 10 \
	    --out docs/images/puget-sound-shadow.png --shaded docs/images/puget-sound-relief.png
	$(BAKE) -q softshadow pipelines/puget-sound-512.ron --sun-azimuth 300 --sun-elevation 3 \
	    --out docs/images/puget-sound-soft-lit.png
	cp $(DOCS_OUT)/cornell-frames/frame_0000.png docs/images/cornell.png
	cp $(DOCS_OUT)/cornell-sun-frames/frame_0001.png docs/images/cornell-sun.png
	cp $(DOCS_OUT)/gltf-room-frames/frame_0000.png docs/images/gltf-room.png
	cp $(DOCS_OUT)/furnished-room-frames/frame_0000.png docs/images/furnished-room.png
	cp $(DOCS_OUT)/terrain-frames/frame_0000.png docs/images/puget-sound-player.png
	for s in csg-holes terrain-16 blobs-128 planet; do \
	    $(BAKE) -q freeform render scenes/freeform/$$s.ron --size 320x240 \
	        --out docs/images/freeform-$$s.png || exit 1; \
	done
	for m in 0 1; do \
	    $(BAKE) -q freeform render scenes/freeform/morph-grid.ron --size 320x240 --morph $$m \
	        --out docs/images/freeform-morph-$$m.png || exit 1; \
	done
	$(PLAYER) scenes/freeform/csg-holes.ron --headless -q --size 320x240 --sun 200,35 \
	    --out $(DOCS_OUT)/freeform-frames
	cp $(DOCS_OUT)/freeform-frames/frame_0000.png docs/images/freeform-player.png
	$(PLAYER) scenes/freeform/column.ron --headless -q --size 320x240 \
	    --out $(DOCS_OUT)/freeform-column-frames
	cp $(DOCS_OUT)/freeform-column-frames/frame_0000.png docs/images/freeform-column.png
	$(PLAYER) scenes/freeform/valley-air.ron --headless -q --size 320x180 \
	    --out $(DOCS_OUT)/freeform-valley-air-frames
	cp $(DOCS_OUT)/freeform-valley-air-frames/frame_0000.png docs/images/freeform-valley-air.png
	$(BAKE) -q study radiosity --out $(DOCS_OUT)/study/radiosity
	$(BAKE) -q study compression --out $(DOCS_OUT)/study/compression
	$(BAKE) -q study terrain --sizes 512,1024,2048 --elevations 5,30 --soft-elevations 2,5 \
	    --soft-rows 64 --out $(DOCS_OUT)/study/terrain
	$(BAKE) -q study atmosphere --paths 40000 --out $(DOCS_OUT)/study/atmosphere
	for s in door-ajar furnished-room; do \
	    $(BAKE) -q study radiosity --scene scenes/generated/$$s.obj --sweeps objects \
	        --objects-reference tests/reference/$$s.mitsuba.json --out $(DOCS_OUT)/study/objects-$$s || exit 1; \
	    cp $(DOCS_OUT)/study/objects-$$s/radiosity_objects_error_vs_patches.png \
	        docs/images/study-objects-$$s.png || exit 1; \
	done
	cp $(DOCS_OUT)/study/atmosphere/atmosphere_error_vs_elevation.png \
	    docs/images/study-atmosphere-error-vs-elevation.png
	for f in radiosity/radiosity_patches_error_vs_time radiosity/radiosity_estimator_error_vs_time \
	         radiosity/radiosity_bounces_error_vs_time compression/compression_reorder_error_vs_time \
	         compression/compression_encoding_error_vs_bytes terrain/terrain_hard_shadows_time_vs_pixels \
	         terrain/terrain_soft_shadows_error_vs_time; do \
	  cp $(DOCS_OUT)/study/$$f.png docs/images/study-$$(basename $$f | tr _ -).png || exit 1; \
	done
	@du -ch docs/images/*.png | tail -1

## Install what the tests need (software Vulkan, Python cross-check readers), then run them all.
test: deps
	@mkdir -p -m 0700 $(XDG_RUNTIME_DIR)
	$(CARGO) test --release --locked
	$(MAKE) --no-print-directory test-slurm

## A real single-node Slurm cluster on this machine (munged, slurmctld, slurmd): a sharded bake
## as job arrays and merges, then again with one task killed and requeued; both merged bakes
## byte-identical to a single-process run (about 40 s; needs root or sudo for the daemons).
test-slurm: build
	scripts/slurm/test-slurm.sh

## GRASS r.sunmask side by side (optional: skips without grass-core; about 4 minutes)
bench-grass:
	scripts/grass/sunmask_compare.sh

deps: deps-apt deps-py deps-npm

deps-apt:
	@missing=""; for p in $(APT_PKGS); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  if command -v apt-get >/dev/null 2>&1; then \
	    echo "installing:$$missing"; \
	    $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get update -qq && \
	    $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing; \
	  else echo "warning: not a Debian system; install$$missing by hand"; fi; \
	fi

deps-py:
	@python3 -c "import PIL, numpy, OpenEXR, tifffile, texture2ddecoder, rasterio, embreex, mitsuba, yaml" 2>/dev/null || { \
	  python3 -m pip install --quiet --disable-pip-version-check $(PY_PKGS) && \
	  python3 -c "import PIL, numpy, OpenEXR, tifffile, texture2ddecoder, rasterio, embreex, mitsuba, yaml"; } || \
	  { echo "error: cannot install the Python cross-check readers ($(PY_PKGS))" >&2; exit 1; }

## The Khronos glTF-Validator for the glTF export's test (Node and npm; pinned in tools/npm).
deps-npm:
	@test -d tools/npm/node_modules/gltf-validator || { \
	  command -v npm >/dev/null 2>&1 || { command -v apt-get >/dev/null 2>&1 && \
	    $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get update -qq && \
	    $(SUDO) env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends nodejs npm; } || \
	    { echo "error: npm is needed for the glTF-Validator (apt-get install nodejs npm)" >&2; exit 1; }; \
	  cd tools/npm && npm ci --no-audit --no-fund --loglevel=error; } || \
	  { echo "error: cannot install the glTF-Validator (tools/npm)" >&2; exit 1; }

## Coverage-guided fuzzing of every reader with AFL++ on stable Rust (docs/fuzzing.md): EXECS
## executions per target (default 10 M; hours on 2 cores), crashes in $(FUZZ_OUT)/<target>/.
FUZZ_OUT     ?= out/fuzz
FUZZ_TARGETS ?= scene heightmap text baked
fuzz:
	@command -v cargo-afl >/dev/null 2>&1 || $(CARGO) install cargo-afl --locked
	@test -d $$HOME/.local/share/afl.rs || $(CARGO) afl config --build
	cd fuzz && $(CARGO) afl build --release
	fuzz/run.sh $(abspath $(FUZZ_OUT)) $(FUZZ_TARGETS)

fmt:
	$(CARGO) fmt --all

## What .ci/run checks before the tests: format, lints (with and without default features).
lint:
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --locked --all-targets -- -D warnings
	$(CARGO) clippy --locked --lib --no-default-features -- -D warnings

bench: build
	$(CARGO) bench --locked

## Speed/accuracy sweeps (docs/algorithms.md §7, docs/study.md): study.json, study.md and PNG plots in
## out/study/{radiosity,compression,terrain,atmosphere}/. Add QUICK=1 for the small sizes (seconds).
study: build
	$(BAKE) study radiosity $(if $(QUICK),--quick) --out out/study/radiosity
	$(BAKE) study compression $(if $(QUICK),--quick) --out out/study/compression
	$(BAKE) study terrain $(if $(QUICK),--quick) --out out/study/terrain
	$(BAKE) study atmosphere $(if $(QUICK),--quick) --out out/study/atmosphere

ci: lint test

clean:
	$(CARGO) clean
	rm -rf out
