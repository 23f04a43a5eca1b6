# Conveniences at the root; the dataset runs themselves are pipeline/Makefile.
#   make demo   set up, then every stage on the synthetic demo scene, to its report
#   make test   set up, then the test suite
#   make run DATASET=lerf-mask DATA_ROOT=/data/lerf_mask [-j3 -k]   a dataset run

.PHONY: demo test run build
demo:
	scripts/demo.sh
test:
	scripts/test.sh
build:
	scripts/setup.sh
run: build
	$(MAKE) -f pipeline/Makefile
