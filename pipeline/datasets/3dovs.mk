# 3DOVS (Liu et al. 2023): ten scenes with LLFF poses (poses_bounds.npy, so
# op2gs-sfm keeps those cameras and only triangulates points), classes from
# segmentations/classes.txt. The segmented views are also training views
# (SPLIT=all) and every view is rendered. Scored as the 3DGS papers and the
# OP2GS paper's 3DOVS table do: the LERF-Mask script on 3DOVS masks, ground
# truth at 1440 px wide (ObjectGS); EVAL_PROTOCOL=3dovs gives the 3DOVS
# reference metric instead. Images are ~4K: trained at 1/4 resolution.

SCENES ?= bed bench blue_sofa covered_desk lawn office_desk room snacks sofa table
SPLIT ?= all
RENDER_VIEWS ?= all
RESOLUTION ?= 4
EVAL_PROTOCOL ?= 3dovs-lerf
EVAL_OPTS ?= --truth-width 1440
DATASET_PAPER := 3dovs
DATASET_LAYOUT := 3dovs
GOALS = $(SCENES) report
