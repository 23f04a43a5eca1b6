# LERF-Mask (Kerr et al.; masks of Gaussian Grouping), as the paper evaluates
# it: three scenes, their query lists (docs/evaluation.md), the
# training views of images_train/, scored with the LERF-Mask script's rules at
# the full resolution of images/. DATA_ROOT is the lerf_mask/ folder exactly
# as Gaussian Grouping ships it: figurines/, ramen/, teatime/, each with
# images/ (undistorted JPEGs), images_train/, sparse/0/, test_mask/<k>/, and
# the DEVA ID maps in object_mask/ that voting uses (sam2/ is used instead
# when it is the only one). object_mask/'s maps of the test views are black
# and unused; distorted/ and stereo/ are ignored; teatime's test view without
# ground truth is skipped, as the reference script skips it, and said so in
# the log and the report.

SCENES ?= figurines ramen teatime
QUERIES_figurines ?= green apple;green toy chair;old camera;porcelain hand;red apple;red toy chair;rubber duck with red hat
QUERIES_ramen ?= chopsticks;egg;glass of water;pork belly;wavy noodles in bowl;yellow bowl
QUERIES_teatime ?= apple;bag of cookies;coffee mug;cookies on a plate;paper napkin;plate;sheep;spoon handle;stuffed bear;tea in a glass
SPLIT ?= lerf
EVAL_PROTOCOL ?= lerf
DATASET_PAPER := lerf-mask
DATASET_LAYOUT := lerf-mask
GOALS = $(SCENES) report
