# muflow -- build, run, test.
#   make run    installs missing Debian packages, builds, runs cases/bagnold.ini
#   make test   installs missing Debian packages, builds and runs the test suite
CC      ?= gcc
OPT     ?= -O3
CFLAGS  ?= $(OPT) -g
# Debian packages muflow needs (headers and libraries); `make deps` installs
# the missing ones with apt-get (as root).
DEB_PKGS = libfftw3-dev libhdf5-dev libgsl-dev libinih-dev libcmocka-dev libsuitesparse-dev pkg-config
PC_PKGS  = fftw3 hdf5 gsl inih
ALL_CFLAGS = -std=c11 -Wall -Wextra -fopenmp -Iinclude $(CFLAGS) \
             $(shell pkg-config --cflags $(PC_PKGS) 2>/dev/null) -I/usr/include/suitesparse
LDLIBS  = -lfftw3_omp $(shell pkg-config --libs $(PC_PKGS) 2>/dev/null) -lcholmod \
          -lsuitesparseconfig -lm
BUILD   ?= build

KERNEL_SRC = $(wildcard kernels/*.c)
LIB_SRC    = $(filter-out src/main.c,$(wildcard src/*.c)) $(KERNEL_SRC)
LIB_OBJ    = $(patsubst %.c,$(BUILD)/obj/%.o,$(LIB_SRC))
TEST_SRC   = $(wildcard tests/*.c)
TEST_OBJ   = $(patsubst %.c,$(BUILD)/obj/%.o,$(TEST_SRC))
HEADERS    = $(wildcard include/*.h tests/*.h)

.PHONY: all deps run test clean check-deps

all: $(BUILD)/muflow

# Installs whatever Debian package is missing; does nothing when all are there.
deps:
	@missing=""; for p in $(DEB_PKGS); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q "ok installed" || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  echo "installing Debian packages:$$missing"; \
	  if [ "$$(id -u)" != 0 ]; then echo "error: need root to apt-get install:$$missing" >&2; exit 1; fi; \
	  DEBIAN_FRONTEND=noninteractive apt-get update -qq && \
	  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing >/dev/null; \
	fi

$(BUILD)/obj/%.o: %.c $(HEADERS)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) -c $< -o $@

$(BUILD)/libmuflow.a: $(LIB_OBJ)
	@rm -f $@
	ar rcs $@ $^

$(BUILD)/muflow: $(BUILD)/obj/src/main.o $(BUILD)/libmuflow.a
	$(CC) $(ALL_CFLAGS) -o $@ $^ $(LDLIBS)

$(BUILD)/muflow_tests: $(TEST_OBJ) $(BUILD)/libmuflow.a
	$(CC) $(ALL_CFLAGS) -o $@ $^ $(LDLIBS) -lcmocka

run: deps
	@$(MAKE) --no-print-directory $(BUILD)/muflow
	$(BUILD)/muflow cases/bagnold.ini

test: deps
	@$(MAKE) --no-print-directory $(BUILD)/muflow $(BUILD)/muflow_tests
	cd tests && ../$(BUILD)/muflow_tests

clean:
	rm -rf $(BUILD) out
