# Your own photos: DATA_ROOT holds one folder per scene, each with images/ and
# sam2/ (one ID map per image, docs/inputs.md); a COLMAP model in
# sparse/0/ is used when present (undistorted first if its cameras have
# distortion, as COLMAP's default SIMPLE_RADIAL has), else the poses of a
# nerfstudio / instant-ngp transforms.json (its points, or points COLMAP
# triangulates), else op2gs-sfm makes one with COLMAP (SFM_OPTS="--max-image-size
# 3200" to find features in phone photos at more than the default 2000 px).
# There is no ground truth, so the run ends with the renders and masks, the
# 3D viewer (<work>/<scene>/viewer/), and, given queries (QUERIES="red
# chair;lamp" for every scene, or QUERIES_<scene>), the objects they select
# (<work>/<scene>/query/query.json), which the viewer then shows.
# When op2gs-sfm undistorted the photos, the masks are also written in the
# photos' own geometry (<work>/<scene>/render/photo/, PHOTO_GEOMETRY), to lay
# over them.

SCENES ?= $(foreach d,$(wildcard $(DATA_ROOT)/*/images),$(notdir $(patsubst %/images,%,$(d))))
QUERIES ?=
$(foreach s,$(SCENES),$(eval QUERIES_$(s) ?= $(QUERIES)))
SPLIT ?= every8
# Stages one and two train at most 1600 px wide, as the 3DGS reference scales
# photos wider than 1.6K (a 12 MP phone photo would take a day); logged by
# op2gs-train. MAX_WIDTH=0 trains at the photos' own width.
MAX_WIDTH ?= 1600
QUERY_MODE := no
DATASET_PAPER := other
DATASET_LAYOUT := photos
GOALS = $(foreach s,$(SCENES),$(s).viewer)
$(foreach s,$(SCENES),$(if $(QUERIES_$(s)),$(eval after_viewer_$(s) := query)))
