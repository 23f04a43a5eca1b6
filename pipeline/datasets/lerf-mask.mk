# LERF-Mask (Kerr et al.; masks of Gaussian Grouping), as the paper evaluates
# it: three scenes, their query lists (docs/evaluation.md), the
# training views of images_train/, scored with the LERF-Mask script's rules at
# the full resolution of images/. DATA_ROOT holds figurines/, ramen/, teatime/
# (images/, images_train/, sparse/0/, test_mask/, and sam2/ ID maps).

SCENES ?= figurines ramen teatime
QUERIES_figurines ?= green apple;green toy chair;old camera;porcelain hand;red apple;red toy chair;rubber duck with red hat
QUERIES_ramen ?= chopsticks;egg;glass of water;pork belly;wavy noodles in bowl;yellow bowl
QUERIES_teatime ?= apple;bag of cookies;coffee mug;cookies on a plate;paper napkin;plate;sheep;spoon handle;stuffed bear;tea in a glass
SPLIT ?= lerf
EVAL_PROTOCOL ?= lerf
DATASET_PAPER := lerf-mask
DATASET_LAYOUT := lerf-mask
GOALS = $(SCENES) report
