# The built-in synthetic demo scene: op2gs-synth ray-traces it (photos without
# a COLMAP model, SAM2-like ID maps with their typical errors, LERF-Mask ground
# truth), then every stage runs, SfM included, on a shortened schedule.
# Not one of the paper's datasets: the report has no published figures.
#
# CLIP: the real ViT-B/16 when its files are in the default folder
# (scripts/get_clip.sh), else the tiny random CLIP of the tests, which runs
# every step; op2gs-eval then marks query mode not available (n/a), as that
# CLIP's answers mean nothing.

DATA_ROOT ?= $(WORK_ROOT)/data
SCENES ?= demo
SYNTH_OPTS ?=
GENERATE = $(BIN)/op2gs-synth $(DATA_ROOT)/$(1) --no-sparse --force $(SYNTH_OPTS)
ITERATIONS ?= 4500
STAGE_ONE ?= 3000
TRAIN_OPTS ?= --densify-until 2250
CLIP ?= $(if $(wildcard $(DEFAULT_CLIP)/model.safetensors),$(DEFAULT_CLIP),$(OP2GS_ROOT)/tests/fixtures/tiny_clip)
DATASET_PAPER := other
DATASET_LAYOUT := lerf-mask
GOALS = $(SCENES) report
