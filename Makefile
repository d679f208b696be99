# muflow -- build, run, test, install.
#   make run    installs missing Debian packages, builds, runs cases/bagnold.ini
#   make test   installs missing Debian packages, builds and runs the test suite
#   make install [PREFIX=/usr/local] [DESTDIR=]   (and make uninstall)
CC      ?= gcc
OPT     ?= -O3
CFLAGS  ?= $(OPT) -g
# Debian packages muflow needs (headers and libraries); `make deps` installs
# the missing ones with apt-get (as root).
DEB_PKGS = libfftw3-dev libhdf5-dev libgsl-dev libinih-dev libcmocka-dev libsuitesparse-dev pkg-config
# xmllint checks fields.xdmf in the tests
DEB_PKGS += libxml2-utils
# an optimised BLAS behind UMFPACK's dense kernels (Debian's default is the
# reference BLAS, 3x slower there); the serial build does not compete with
# muflow's OpenMP threads
DEB_PKGS += libopenblas0-serial
# tools/muflow_plot.py (Debian's /usr/bin/python3 with numpy, matplotlib,
# h5py), which the tools test group runs
DEB_PKGS += python3-matplotlib python3-h5py
# hypre's BoomerAMG (the amg preconditioner, src/solvers/amg_hypre.c); Debian
# builds it with OpenMPI, so MPI's headers and library come along (one rank);
# the headers give amg_hypre.c its types, the libraries are opened at run time
DEB_PKGS += libhypre-dev libopenmpi-dev
# libopenmpi-dev also brings openmpi-bin (mpirun, Depends): the tests' mpi
# group runs under it; src/platform/comm.c opens libmpi only under mpirun
# the parallel HDF5 of the ranks' field files (src/platform/phdf5.c opens it
# only under mpirun; muflow links the serial one, named hdf5-serial: this
# package turns pkg-config's hdf5 to the MPI flavour)
DEB_PKGS += libhdf5-openmpi-dev
# FFTW's MPI transforms, the ranks' pressure (src/platform/fft_ranks.c opens
# it only under mpirun: it needs libmpi)
DEB_PKGS += libfftw3-mpi-dev
PC_PKGS  = fftw3 hdf5-serial gsl inih
PC_CFLAGS_PKGS = $(PC_PKGS) ompi-c
ALL_CFLAGS = -std=c11 -Wall -Wextra -fopenmp -Iinclude $(CFLAGS) \
             $(shell pkg-config --cflags $(PC_CFLAGS_PKGS) 2>/dev/null) -I/usr/include/suitesparse \
             -I/usr/include/hypre
LDLIBS  = -lfftw3_omp $(shell pkg-config --libs $(PC_PKGS) 2>/dev/null) -lm
# the executables' GOMP_parallel (src/platform/gomp_inline.c) is the one the
# libraries opened later bind to: CHOLMOD's regions run inline on one thread
# (fftw3_omp's reference to it exports it too; this does not rely on that)
LDLIBS += -Wl,--export-dynamic-symbol=GOMP_parallel
# and so is its SuiteSparse_time (src/platform/suitesparse_clock.c, taken from
# the archive though nothing in muflow calls it): CHOLMOD's clock, stopped
LDLIBS += -Wl,--undefined=SuiteSparse_time -Wl,--export-dynamic-symbol=SuiteSparse_time
# hypre (and its OpenMPI) is not linked: amg_hypre.c opens it with dlopen when
# the first AMG is created (every other run starts sooner, with fewer shared
# libraries: docs/numerics/threads-and-platform.md), by the soname
# the -dev package's libHYPRE.so points to; mpi.h and hypre's headers give the
# types.  ompi-c is only in the Cflags' packages.
MULTIARCH := $(shell $(CC) -print-multiarch)
HYPRE_LIB := $(notdir $(realpath $(shell $(CC) -print-file-name=libHYPRE.so)))
# SuiteSparse's CHOLMOD and UMFPACK are not linked either (suitesparse_open.c
# opens them with the first sparse factorisation: they and their BLAS were over
# half of the loader's relocations); their sonames come from the -dev package.
soname = $(shell objdump -p $(shell $(CC) -print-file-name=$(1)) 2>/dev/null | awk '/SONAME/ {print $$2}')
CHOLMOD_LIB := $(call soname,libcholmod.so)
UMFPACK_LIB := $(call soname,libumfpack.so)
MPI_LIB     := $(call soname,libmpi.so)
PHDF5_LIB   := $(call soname,hdf5/openmpi/libhdf5.so)
FFTW_MPI_LIB := $(call soname,libfftw3_mpi.so)
BUILD   ?= build

# The version, defined here only: `git describe` of a release tag vX.Y.Z when
# there is one (e.g. 0.2.0-3-gabc1234-dirty), else the VERSION file.
VERSION := $(shell v=$$(git describe --tags --match 'v[0-9]*' --dirty 2>/dev/null) && \
             echo "$$v" | sed 's/^v//' || cat VERSION)

KERNEL_SRC = $(wildcard kernels/*.c)
LIB_SRC    = $(filter-out src/app/main.c,$(wildcard src/*/*.c)) $(KERNEL_SRC)
LIB_OBJ    = $(patsubst %.c,$(BUILD)/obj/%.o,$(LIB_SRC))
TEST_SRC   = $(wildcard tests/*.c)
TEST_OBJ   = $(patsubst %.c,$(BUILD)/obj/%.o,$(TEST_SRC))
HEADERS    = $(wildcard include/*/*.h src/*/*.h kernels/*.h tests/*.h tests/fuzz/*.h)

.PHONY: all deps run test clean check-deps check-asan fuzz install uninstall print-version print-deb-pkgs \
        case-keys docs FORCE

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

# main.c prints the version: rebuilt when it changes ($(BUILD)/version holds it)
FORCE:
$(BUILD)/version: FORCE
	@mkdir -p $(dir $@)
	@echo '$(VERSION)' | cmp -s - $@ || echo '$(VERSION)' > $@
$(BUILD)/obj/src/app/main.o: $(BUILD)/version
$(BUILD)/obj/src/app/main.o: ALL_CFLAGS += -DMUFLOW_VERSION='"$(VERSION)"'
# the hypre library amg_hypre.c opens (HYPRE_LIB above)
$(BUILD)/obj/src/solvers/amg_hypre.o: ALL_CFLAGS += $(if $(HYPRE_LIB),-DMUFLOW_HYPRE_LIB='"$(HYPRE_LIB)"')
# Debian's serial OpenBLAS, which blas.c opens before the libraries that use
# a BLAS (the alternatives may point libblas.so.3 to a threaded build)
$(BUILD)/obj/src/platform/blas.o: ALL_CFLAGS += -DMUFLOW_SERIAL_BLAS_DIR='"/usr/lib/$(MULTIARCH)/openblas-serial"'
# the libmpi comm.c opens under mpirun (MPI_LIB above)
$(BUILD)/obj/src/platform/comm.o: ALL_CFLAGS += $(if $(MPI_LIB),-DMUFLOW_MPI_LIB='"$(MPI_LIB)"')
$(BUILD)/obj/tests/test_mpi_traffic.o: ALL_CFLAGS += $(if $(MPI_LIB),-DMUFLOW_MPI_LIB='"$(MPI_LIB)"')
# the parallel HDF5 phdf5.c opens under mpirun (PHDF5_LIB above)
$(BUILD)/obj/src/platform/phdf5.o: ALL_CFLAGS += $(if $(PHDF5_LIB),-DMUFLOW_PHDF5_LIB='"$(PHDF5_LIB)"')
# the FFTW MPI library fft_ranks.c opens under mpirun (FFTW_MPI_LIB above)
$(BUILD)/obj/src/platform/fft_ranks.o: ALL_CFLAGS += $(if $(FFTW_MPI_LIB),-DMUFLOW_FFTW_MPI_LIB='"$(FFTW_MPI_LIB)"')
# the SuiteSparse libraries suitesparse_open.c opens (CHOLMOD_LIB, UMFPACK_LIB above)
$(BUILD)/obj/src/platform/suitesparse_open.o: ALL_CFLAGS += $(if $(CHOLMOD_LIB),-DMUFLOW_CHOLMOD_LIB='"$(CHOLMOD_LIB)"') \
                                                         $(if $(UMFPACK_LIB),-DMUFLOW_UMFPACK_LIB='"$(UMFPACK_LIB)"')

print-version:
	@echo '$(VERSION)'

# the package list README's "Two commands" must name (the tools test group)
print-deb-pkgs:
	@echo '$(DEB_PKGS)'

$(BUILD)/muflow: $(BUILD)/obj/src/app/main.o $(BUILD)/libmuflow.a
	$(CC) $(ALL_CFLAGS) -o $@ $^ $(LDLIBS)

# examples/minimal.c, the library's smallest program (the tools tests build
# it against the installed library with pkg-config, as its comment says)
$(BUILD)/minimal: $(BUILD)/obj/examples/minimal.o $(BUILD)/libmuflow.a
	$(CC) $(ALL_CFLAGS) -o $@ $^ $(LDLIBS)

# tests/test_mpi_traffic.c's MPI calls of FFTW's library, seen first
TEST_EXPORTS = $(foreach f,MPI_Alltoall MPI_Alltoallv MPI_Sendrecv MPI_Send,\
                 -Wl,--export-dynamic-symbol=$(f))
$(BUILD)/muflow_tests: $(TEST_OBJ) $(BUILD)/libmuflow.a
	$(CC) $(ALL_CFLAGS) -o $@ $^ $(LDLIBS) $(TEST_EXPORTS) -lcmocka

MPIRUN = OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1 \
         OMP_WAIT_POLICY=passive mpirun -x OMP_NUM_THREADS -x OMP_WAIT_POLICY

run: deps
	@$(MAKE) --no-print-directory $(BUILD)/muflow
	$(BUILD)/muflow cases/bagnold.ini

test: deps
	@$(MAKE) --no-print-directory $(BUILD)/muflow $(BUILD)/muflow_tests
	# passive waiting: a busy machine must not turn OpenMP barriers into spin contests
	cd tests && OMP_WAIT_POLICY=passive ../$(BUILD)/muflow_tests
	# the decomposition on 2 and 4 ranks (one thread each; as root in CI)
	cd tests && $(MPIRUN) -np 2 ../$(BUILD)/muflow_tests mpi
	cd tests && $(MPIRUN) -np 4 --oversubscribe ../$(BUILD)/muflow_tests mpi

clean:
	rm -rf $(BUILD) out

# docs/case_keys.md is generated from the key tables (src/config/case.c and
# each scene's key block); the case tests check that it is current.
case-keys: $(BUILD)/muflow
	$(BUILD)/muflow --list=markdown > docs/case_keys.md.tmp
	mv docs/case_keys.md.tmp docs/case_keys.md
docs: case-keys

# ---- install ------------------------------------------------------------------
# The command, the library, its headers (include/ as PREFIX/include/muflow/,
# so `#include "config/case.h"` as in the tree) and muflow.pc:
#   cc prog.c $(pkg-config --cflags --libs muflow)
# DESTDIR stages the tree elsewhere (packaging); muflow.pc names PREFIX.
PREFIX     ?= /usr/local
BINDIR     ?= $(PREFIX)/bin
LIBDIR     ?= $(PREFIX)/lib
INCLUDEDIR ?= $(PREFIX)/include
PCDIR      ?= $(LIBDIR)/pkgconfig
PUBLIC_HEADERS = $(wildcard include/*/*.h)

# muflow.pc names the PREFIX, LIBDIR and INCLUDEDIR of this make invocation:
# rebuilt when one of them changes ($(BUILD)/install-dirs holds them, as
# $(BUILD)/version holds the version)
INSTALL_DIRS = prefix=$(PREFIX) libdir=$(LIBDIR) includedir=$(INCLUDEDIR)
$(BUILD)/install-dirs: FORCE
	@mkdir -p $(dir $@)
	@printf '%s\n' '$(INSTALL_DIRS)' | cmp -s - $@ || printf '%s\n' '$(INSTALL_DIRS)' > $@

$(BUILD)/muflow.pc: Makefile $(BUILD)/version $(BUILD)/install-dirs
	@mkdir -p $(dir $@)
	@{ echo 'prefix=$(PREFIX)'; \
	   echo 'libdir=$(if $(filter $(PREFIX)/%,$(LIBDIR)),$${prefix}/$(patsubst $(PREFIX)/%,%,$(LIBDIR)),$(LIBDIR))'; \
	   echo 'includedir=$(if $(filter $(PREFIX)/%,$(INCLUDEDIR)),$${prefix}/$(patsubst $(PREFIX)/%,%,$(INCLUDEDIR)),$(INCLUDEDIR))'; \
	   echo ''; \
	   echo 'Name: muflow'; \
	   echo 'Description: solver for dense granular flows (mu(I) rheology) on a staggered grid'; \
	   echo 'Version: $(VERSION)'; \
	   echo 'Requires: $(PC_PKGS)'; \
	   echo 'Cflags: -fopenmp -I$${includedir}/muflow -I/usr/include/suitesparse'; \
	   echo 'Libs: -fopenmp -L$${libdir} -lmuflow $(filter-out $(shell pkg-config --libs $(PC_PKGS) 2>/dev/null),$(LDLIBS)) -lm'; \
	} > $@

install: $(BUILD)/muflow $(BUILD)/libmuflow.a $(BUILD)/muflow.pc
	install -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(LIBDIR) $(DESTDIR)$(PCDIR) \
	  $(addprefix $(DESTDIR)$(INCLUDEDIR)/muflow/,$(sort $(notdir $(patsubst %/,%,$(dir $(PUBLIC_HEADERS))))))
	install -m 755 $(BUILD)/muflow $(DESTDIR)$(BINDIR)/muflow
	install -m 644 $(BUILD)/libmuflow.a $(DESTDIR)$(LIBDIR)/libmuflow.a
	for h in $(PUBLIC_HEADERS); do \
	  install -m 644 $$h $(DESTDIR)$(INCLUDEDIR)/muflow/$${h#include/} || exit 1; \
	done
	install -m 644 $(BUILD)/muflow.pc $(DESTDIR)$(PCDIR)/muflow.pc

uninstall:
	rm -f $(DESTDIR)$(BINDIR)/muflow $(DESTDIR)$(LIBDIR)/libmuflow.a $(DESTDIR)$(PCDIR)/muflow.pc
	rm -rf $(DESTDIR)$(INCLUDEDIR)/muflow

# AddressSanitizer + UBSan: a separate build in build/asan, the unit tests
# (every group but the long scenes) and the shipped profile scenes from the
# command line; any report fails the target (-fno-sanitize-recover, leaks too).
ASAN_BUILD  = build/asan
ASAN_FLAGS  = -O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer \
              -fno-sanitize-recover=all
ASAN_GROUPS = rheology poisson multigrid case viscous heap io corpus vof architecture two_phase bedload collapse front boundary duct obstacle forces stretched scenes bingham cases depth_averaged ngf time_scheme slope_release mpi wall_shock
ASAN_ENV    = ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
              LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp
# the tests run the plain build/muflow for their command-line checks (a
# fresh clone has none until it is built)
check-asan: deps $(BUILD)/muflow
	@$(MAKE) --no-print-directory BUILD=$(ASAN_BUILD) CFLAGS="$(ASAN_FLAGS)" \
	  $(ASAN_BUILD)/muflow $(ASAN_BUILD)/muflow_tests
	cd tests && $(ASAN_ENV) ../$(ASAN_BUILD)/muflow_tests $(ASAN_GROUPS)
	# hypre's OpenMPI crashes LeakSanitizer's exit-time scan: amg without leak detection
	cd tests && $(ASAN_ENV) ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 \
	  ../$(ASAN_BUILD)/muflow_tests amg
	for c in bagnold chute; do \
	  $(ASAN_ENV) $(ASAN_BUILD)/muflow cases/$$c.ini output.dir=$(ASAN_BUILD)/out/$$c \
	    output.quiet=on || exit 1; \
	done

# libFuzzer on case_load (file + overrides, tests/fuzz/fuzz_case.c) with
# AddressSanitizer and UBSan, for FUZZ_SECONDS; the inputs that add coverage
# are merged into tests/fuzz/corpus (replayed by the "corpus" test group).
FUZZ_PKGS    = clang libclang-rt-14-dev
FUZZ_CC      = clang
FUZZ_SECONDS ?= 60
FUZZ_BUILD   = build/fuzz
# case_load needs the scene registry (each scene's own keys), so the target
# links the whole library, compiled with the fuzzer's instrumentation
FUZZ_SRC     = tests/fuzz/fuzz_case.c $(LIB_SRC)
FUZZ_FLAGS   = -std=c11 -Wall -Wextra -g -O1 -fopenmp -Iinclude -I/usr/include/suitesparse \
               -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all
$(FUZZ_BUILD)/fuzz_case: $(FUZZ_SRC) $(HEADERS)
	@mkdir -p $(FUZZ_BUILD)
	$(FUZZ_CC) $(FUZZ_FLAGS) $(shell pkg-config --cflags $(PC_CFLAGS_PKGS) 2>/dev/null) -I/usr/include/hypre \
	  $(FUZZ_SRC) -o $@ \
	  $(LDLIBS)
fuzz:
	@$(MAKE) --no-print-directory deps DEB_PKGS="$(DEB_PKGS) $(FUZZ_PKGS)"
	@$(MAKE) --no-print-directory $(FUZZ_BUILD)/fuzz_case
	@mkdir -p $(FUZZ_BUILD)/corpus
	$(FUZZ_BUILD)/fuzz_case -max_total_time=$(FUZZ_SECONDS) -dict=tests/fuzz/case.dict \
	  -artifact_prefix=$(FUZZ_BUILD)/ -print_final_stats=1 $(FUZZ_BUILD)/corpus tests/fuzz/corpus
	$(FUZZ_BUILD)/fuzz_case -merge=1 tests/fuzz/corpus $(FUZZ_BUILD)/corpus

# ---- benchmarks (bench/; docs/benchmarks.md) ----------------------------------
# `make bench` installs the plotting package (Debian's matplotlib, used through
# /usr/bin/python3), builds the bench programs against build/libmuflow.a with
# the flags above, runs every benchmark on 2 threads (several minutes, most of
# it bench_multigrid's 256^3 solves, which need ~2.3 GiB; bench_process runs
# whole `muflow CASE` processes) and writes bench/out/report.md with its PNG
# plots, printing the tables.
BENCH_PKGS    = python3-matplotlib python3-h5py
BENCH_OUT     ?= bench/out
BENCH_REPEATS ?= 7
# bench_process: whole `muflow CASE` processes (fork, exec, wait4), PROCESS_REPEATS
# runs of each configuration after a warm-up (about a minute on 2 idle cores)
PROCESS_REPEATS ?= 21
BENCH_PROGS   = $(BUILD)/bench_scenes $(BUILD)/bench_throughput $(BUILD)/bench_multigrid \
                $(BUILD)/bench_process
BENCH_OBJ     = $(patsubst %.c,$(BUILD)/obj/%.o,$(wildcard bench/*.c))

.PHONY: bench bench-deps

bench-deps:
	@$(MAKE) --no-print-directory deps DEB_PKGS="$(BENCH_PKGS)"

$(BENCH_OBJ): bench/bench.h

$(BUILD)/bench_%: $(BUILD)/obj/bench/bench_%.o $(BUILD)/obj/bench/bench.o $(BUILD)/libmuflow.a
	$(CC) $(ALL_CFLAGS) -o $@ $^ $(LDLIBS)

bench: deps bench-deps
	@$(MAKE) --no-print-directory $(BENCH_PROGS) $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 $(BUILD)/bench_process $(BENCH_OUT) $(PROCESS_REPEATS) $(BUILD)/muflow
	OMP_NUM_THREADS=2 $(BUILD)/bench_scenes $(BENCH_OUT) $(BENCH_REPEATS)
	OMP_NUM_THREADS=2 $(BUILD)/bench_throughput $(BENCH_OUT)
	OMP_NUM_THREADS=2 OMP_WAIT_POLICY=passive $(BUILD)/bench_multigrid $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/bagnold2_study.py $(BUILD)/muflow $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/bedload_study.py $(BUILD)/muflow $(BENCH_OUT)
	OMP_NUM_THREADS=2 OMP_WAIT_POLICY=passive /usr/bin/python3 bench/scene_times.py $(BUILD)/muflow $(BENCH_OUT)
	/usr/bin/python3 bench/report.py $(BENCH_OUT)

# Threads on a busy machine: every case file (the long ones bounded: see the
# script) at the default 2 threads, on 1 thread and on 2 passive threads,
# alternating, THREADS_REPEATS times each, on the idle machine and beside two
# processes that keep both cores busy; $(BENCH_OUT)/threads_busy.md.  About
# 15 minutes on 2 cores.
THREADS_REPEATS ?= 3
# The decomposed multigrid (bench/bench_decomposed.c): 64^3 and 128^3 on 1,
# 2 and 4 ranks of one thread, DECOMP_REPEATS solves each: time, halo and
# gather traffic measured and modelled, memory per cell; 16^3 on one rank
# (the gathered level's serial cycle alone) (decomposed.txt);
# then bench/decomposed_scaling.py projects weak and strong scaling to 1,024
# ranks (decomposed_scaling.md, .png).  A few minutes on 2 cores.
DECOMP_REPEATS ?= 3
.PHONY: bench-decomposed
bench-decomposed: deps bench-deps
	@$(MAKE) --no-print-directory $(BUILD)/bench_decomposed
	@mkdir -p $(BENCH_OUT)
	{ OMP_NUM_THREADS=1 $(BUILD)/bench_decomposed 16 20 || exit 1; \
	for n in 64 128; do \
	  OMP_NUM_THREADS=1 $(BUILD)/bench_decomposed $$n $(DECOMP_REPEATS) || exit 1; \
	  for p in 2 4; do \
	    $(MPIRUN) -np $$p --oversubscribe $(BUILD)/bench_decomposed $$n $(DECOMP_REPEATS) || exit 1; \
	  done; done; } > $(BENCH_OUT)/decomposed.txt
	/usr/bin/python3 bench/decomposed_scaling.py $(BENCH_OUT)

# The plane Fourier line blocks over ranks: bagnold3d 128 x 128 x 64 on 2
# ranks x 1 thread, each step's traffic against its model, its shares in
# MPI's calls and the peak RSS a rank (bench/bench_step_traffic.c,
# $(BENCH_OUT)/fourier_traffic.txt); then FOURIER_STEPS steps on 2 x 1 and
# 1 x 2, alternated, FOURIER_REPEATS runs each (bench/fourier_ranks_bench.py:
# medians, peak RSS a rank, load, $(BENCH_OUT)/fourier_ranks.md), whose last
# line is the ratio of the speeds.  About 6 minutes on 2 cores.
FOURIER_REPEATS ?= 3
FOURIER_STEPS ?= 3
.PHONY: bench-fourier-ranks
bench-fourier-ranks: deps $(BUILD)/muflow $(BUILD)/bench_step_traffic
	@mkdir -p $(BENCH_OUT)
	$(MPIRUN) -np 2 $(BUILD)/bench_step_traffic cases/bagnold3d.ini \
	  solver.max_steps=$(FOURIER_STEPS) > $(BENCH_OUT)/fourier_traffic.txt
	cat $(BENCH_OUT)/fourier_traffic.txt
	OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 /usr/bin/python3 \
	  bench/fourier_ranks_bench.py $(BUILD)/muflow $(BENCH_OUT) $(FOURIER_REPEATS) \
	  $(FOURIER_STEPS) mpirun --oversubscribe

.PHONY: bench-threads
bench-threads: deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	/usr/bin/python3 bench/threads_busy.py $(BUILD)/muflow $(BENCH_OUT) --repeats $(THREADS_REPEATS)

# The Bingham cavity study: psi_max and the mid-line profile against Vola et
# al. (2003) for their Bn = 0, 1, 10, 100, 1000, and the yielded regions at
# Bn = 2, 5, 20 (muflow's convention), as PNG plots and CSV tables in
# $(BENCH_OUT); CAVITY_OPTS are case overrides (section.key=value) for every
# run.  Then `make bench` (or bench/report.py) puts the table in the report.
CAVITY_N    ?= 64
CAVITY_BN   ?= 0 0.70710678118654752 7.0710678118654752 70.710678118654752 \
               707.10678118654752 2 5 20
CAVITY_OPTS ?=
.PHONY: bench-cavity bench-cavity-128
bench-cavity: deps bench-deps
	@$(MAKE) --no-print-directory $(BUILD)/bench_cavity
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 $(BUILD)/bench_cavity $(BENCH_OUT) $(CAVITY_N) $(CAVITY_OPTS) $(CAVITY_BN)
	/usr/bin/python3 bench/plot_cavity.py $(BENCH_OUT)

# 128 x 128 for Vola's Bn = 0, 1, 10, 100, 1000 (minutes each), from rest with
# the case's defaults (docs/numerics/steady-criterion.md, "Globalisation").
bench-cavity-128: deps bench-deps
	@$(MAKE) --no-print-directory $(BUILD)/bench_cavity
	@mkdir -p $(BENCH_OUT)/cavity128
	OMP_NUM_THREADS=2 $(BUILD)/bench_cavity $(BENCH_OUT)/cavity128 128 0 0.70710678118654752 \
	  7.0710678118654752 70.710678118654752 707.10678118654752
	cp $(BENCH_OUT)/cavity128/cavity_table_n128.csv $(BENCH_OUT)/

# The heap study: the tilt for the experiment's flow rates Q* = 14.9, 40.2 and
# 90.1 at 70 x 100, the mesh study for Q* = 40.2 (35 x 50, 70 x 100,
# 140 x 200), and the plots (surface velocity, flowing depth, velocity maps);
# bench/out/heap_table.md.  About half an hour on 2 idle cores.
.PHONY: bench-heap
bench-heap: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/heap_study.py $(BUILD)/muflow $(BENCH_OUT)

# The nonlocal fluidity's steady cost against the local law's, medians of 5
# alternated runs on one thread (bench/ngf_cost.py: bench/out/ngf_cost.md),
# then its stopping height at five angles on 10, 20, 40 cells by bisection
# against the closed form, and the flow rule above it (bench/ngf_hstop.py);
# bench/out/ngf_hstop.md.  5 minutes on one thread.
.PHONY: bench-ngf
bench-ngf: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=1 /usr/bin/python3 bench/ngf_cost.py $(BUILD)/muflow $(BENCH_OUT)
	OMP_NUM_THREADS=1 /usr/bin/python3 bench/ngf_hstop.py $(BUILD)/muflow $(BENCH_OUT) \
	  rheology.lambda=1e-12

# The algebraic multigrid against the probed LU on whole steady solves
# (bench/heap_amg.py): the heap at the tilt 0.4061 on 140 x 200 with lu,
# amg and gmg alternating (AMG_REPEATS each: wall and CPU time, peak memory,
# steps, the load average beside each run), 280 x 400 with amg, gmg and lu
# to their steady states, the Krylov iterations per Newton step of the heap
# (35 x 50 to 280 x 400, amg and gmg) and of the Bingham cavity (32 x 32 to
# 256 x 256: the AMG's first 8 steps, and whole solves of the coupled step
# by GMRES); bench/out/amg_table.md.  About 30 minutes on 2 idle cores, most
# of it the LU runs and the coupled 256 x 256 cavity.
AMG_REPEATS ?= 2
.PHONY: bench-amg
bench-amg: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/heap_amg.py $(BUILD)/muflow $(BENCH_OUT) --repeats $(AMG_REPEATS)

# The duct studies (Chauchat & Medale 2010, sec. 4): cases/duct_square.ini and
# cases/duct_circular.ini, both models, on the half cross-section meshes
# 10 x 20, 20 x 40, 40 x 80 (the paper's square meshes) and 80 x 160.  At
# 80 x 160 the mixed model starts from the 40 x 80 solution
# (solver.initial_state, at dt 0.001 with the probed LU), the two-fluid
# model from rest like the coarser meshes.  The
# tables of flow rates and mid-plane differences (bench/out/duct_table*.md,
# duct_circular_table*.md) and the plots duct*_midplane*.png (figs. 11, 14),
# duct*_map*.png (figs. 10, 13) and duct*_phases_two_fluid.png (figs. 12,
# 15).  About a minute on 2 cores.
DUCT_COARSE = 10x20,20x40,40x80
DUCT_MESHES = $(DUCT_COARSE),80x160:solver.initial_state=previous:solver.dt=0.001:solver.preconditioner=lu
DUCT_MESHES_TWO_FLUID = $(DUCT_COARSE),80x160
.PHONY: bench-duct
bench-duct: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	for c in cases/duct_square.ini cases/duct_circular.ini; do \
	  OMP_NUM_THREADS=2 /usr/bin/python3 bench/duct_study.py $(BUILD)/muflow $(BENCH_OUT) \
	    --case $$c --meshes $(DUCT_MESHES) || exit 1; \
	  OMP_NUM_THREADS=2 /usr/bin/python3 bench/duct_study.py $(BUILD)/muflow $(BENCH_OUT) \
	    --case $$c --model two_fluid --meshes $(DUCT_MESHES_TWO_FLUID) || exit 1; done

# The 3D steady flow: cases/bagnold3d.ini, bagnold on 128 x 128 x 64 =
# 1,048,576 cells from rest plus a divergence-free 3D perturbation, to its
# steady state on 2 threads, beside the 1D run of the same nz: wall time,
# steps, peak memory, err_rms of both and the load average before and after
# ($(BENCH_OUT)/bagnold3d.md).  About 5 minutes and 0.7 GB on 2 shared
# cores; BAGNOLD3D_OPTS are case overrides (a quick one: domain.nx=8 domain.ny=8
# domain.nz=16 domain.lx=7 domain.ly=7, the test's grid).
BAGNOLD3D_OPTS ?=
.PHONY: bench-3d
bench-3d: deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/bagnold3d_bench.py $(BUILD)/muflow $(BENCH_OUT) \
	  $(BAGNOLD3D_OPTS)

# The Schaefer & Turek 2D-1 cylinder (Re 20): cases/cylinder_benchmark.ini
# on D/h = CYLINDER_GRIDS, C_D (surface integral and control volume), C_L and
# the pressure difference against the reference, observed orders
# ($(BENCH_OUT)/cylinder_table.md, cylinder_surface.png).  About 40 minutes
# on 2 cores, most of it D/40.
CYLINDER_GRIDS ?= 10,20,40
.PHONY: bench-cylinder
bench-cylinder: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/cylinder_study.py $(BUILD)/muflow $(BENCH_OUT) \
	  --grids $(CYLINDER_GRIDS) --plot

# The granular cylinder (cases/cylinder.ini, half box at D/4): one steady
# solve from rest with the continuation in lambda (its wall time), then the
# continuation in the forcing F for the confining pressures
# GRANULAR_PRESSURES (the first along GRANULAR_FORCING, each F from the
# secant of the two before, the step halved on failure down to 0.0125: the
# limit; the others from its states scaled to their pressure), with
# $(BENCH_OUT)/cylinder_granular.csv, cylinder_granular.png (fig. 12) and
# cylinder_granular_maps.png (figs. 13, 14, 16).  Hours on 2 cores
# (docs/validation/cylinder.md).
GRANULAR_PRESSURES ?= 10,5,20,2.5,40
GRANULAR_FORCING ?= 1.0,1.05,1.1,1.15,1.2,1.25,1.3,1.35,1.4,1.45,1.5,1.55
.PHONY: bench-cylinder-granular
bench-cylinder-granular: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/cylinder_granular.py $(BUILD)/muflow $(BENCH_OUT) \
	  --pressures $(GRANULAR_PRESSURES) --forcing $(GRANULAR_FORCING) --reuse --plot

# Grid convergence of the granular cylinder's drag at F = 1 (cases/cylinder.ini,
# lambda 1e-2 on every grid): D/h = GRANULAR_GRIDS, the first from rest,
# each finer one from the state before it, with the sheared layer at the
# body ($(BENCH_OUT)/cylinder_grids.md, cylinder_grids_layer.png).  About
# 5 minutes on 2 cores to D/16; D/32 takes 40 more and 14 GB
# (docs/validation/cylinder.md).
GRANULAR_GRIDS ?= 4,8,16
.PHONY: bench-cylinder-grids
bench-cylinder-grids: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/cylinder_grids.py $(BUILD)/muflow $(BENCH_OUT) \
	  --grids $(GRANULAR_GRIDS)

# The same study on stretched grids: D/h within 1.5 D of the cylinder's
# centre (domain.x_band, z_band), D/4 far from it, h over GRANULAR_BANDS
# (docs/validation/cylinder.md): $(BENCH_OUT)/cylinder_bands.md.
GRANULAR_BANDS ?= 8,16,32,64
.PHONY: bench-cylinder-bands
bench-cylinder-bands: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/cylinder_grids.py $(BUILD)/muflow $(BENCH_OUT) \
	  --grids $(GRANULAR_BANDS) --band 1.5

# The granular cylinder's continuation in F in one run (scene cylinder,
# cases/cylinder.ini: D/4, p_ext = 10, lambda 1e-6; from rest at F = 1 to
# CYLINDER_FORCING_END in steps of 0.05, 2 threads): the time of each steady
# solve and of the whole continuation, $(BENCH_OUT)/cylinder_continuation/
# cylinder.csv.  About 6 minutes to 1.2 (docs/benchmarks.md).
CYLINDER_FORCING_END ?= 1.2
.PHONY: bench-cylinder-continuation
bench-cylinder-continuation: deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 $(BUILD)/muflow cases/cylinder.ini \
	  cylinder.forcing_end=$(CYLINDER_FORCING_END) cylinder.forcing_step=0.05 \
	  output.fields=off output.dir=$(BENCH_OUT)/cylinder_continuation
	@cat $(BENCH_OUT)/cylinder_continuation/cylinder.csv

# The granular front fed by a uniform layer (cases/front.ini) on FRONT_NZ
# cells over the box's height (nx = 50 nz / 3): the front speed, h(x) in the
# front's frame against Pouliquen's closed form and the profile behind
# against Bagnold's ($(BENCH_OUT)/front_table.md, front_compare.png;
# docs/validation/front.md).
FRONT_NZ ?= 10 15 24
.PHONY: bench-front
bench-front: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/front_study.py $(BUILD)/muflow $(BENCH_OUT) $(FRONT_NZ)

# The shock from a wall (cases/wall_shock.ini) on WALL_SHOCK_NX cells along
# the box (nz = 3 nx / 4: 5, 10, 20 cells per h1): its speed and depth ratio
# against the jump conditions with u2 = 0 and with the measured creep u2,
# against the depth-averaged equations' solution, the 2D speed's Richardson
# estimate, and that solution's convergence on 5 to 80 cells per h1
# ($(BENCH_OUT)/wall_shock_table.md; docs/validation/wall_shock.md).  About
# 12 minutes on 2 idle cores, most of it nx = 160.
WALL_SHOCK_NX ?= 40 80 160
.PHONY: bench-wall-shock
bench-wall-shock: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/wall_shock_study.py $(BUILD)/muflow $(BENCH_OUT) \
	  $(WALL_SHOCK_NX)

# The column collapse study: cases/collapse.ini (a = 0.5) to t = 4 at
# COLLAPSE_N cells per H0, x_f(t) and h(0,t) against the Basilisk
# reference, the grid convergence of x_f(4), wall time on 2 threads, steps
# and cell-steps per second ($(BENCH_OUT)/collapse_table.md,
# collapse_front.png); the same with the granular viscosity clipped to
# [d sqrt(g d), 1e4] and advected by van Leer's scheme
# (collapse_table_clip.md); then the deposits of a = 0.5,
# 1.42 and 6.26 at
# COLLAPSE_DEPOSIT_N cells per H0 against contact dynamics
# (collapse_deposits.md, collapse_deposit_a*.png), without and with the
# clip.  About 4 minutes on 2 idle cores, most of it the two runs at N = 64.
COLLAPSE_N ?= 16 32 64
COLLAPSE_DEPOSIT_N ?= 32
# The published set-up: the clip, and van Leer's second-order advection,
# which the clip's floor on the viscosity keeps from shedding grains at the
# front (without the clip the case keeps the donor cell:
# docs/numerics/two-phase-and-vof.md).
COLLAPSE_CLIP = collapse.viscosity_clip=on collapse.eta_max=1e4 physics.advection_scheme=vanleer
.PHONY: bench-collapse
bench-collapse: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/collapse_study.py $(BUILD)/muflow $(BENCH_OUT) $(COLLAPSE_N)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/collapse_study.py $(BUILD)/muflow $(BENCH_OUT) $(COLLAPSE_N) \
	  $(COLLAPSE_CLIP) --tag clip
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/collapse_deposits.py $(BUILD)/muflow $(BENCH_OUT) \
	  $(COLLAPSE_DEPOSIT_N)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/collapse_deposits.py $(BUILD)/muflow $(BENCH_OUT) \
	  $(COLLAPSE_DEPOSIT_N) $(COLLAPSE_CLIP) --tag clip

# The time step's share of the collapse's late front: the study above with
# the defaults and with the nonlocal fluidity (COLLAPSE_NGF, the parameters of
# docs/validation/collapse.md) at each cap in COLLAPSE_DTS, one table a cap
# and law ($(BENCH_OUT)/collapse_table_dt*.md, collapse_table_ngf_dt*.md; x_f(4)
# in their grid convergence).  About 20 minutes on 2 cores, most of it the
# runs at N = 64 and the smallest cap.
COLLAPSE_DTS ?= 0.01 0.0025 0.00125
COLLAPSE_NGF = rheology.law=ngf rheology.nonlocal_b=0.7
.PHONY: bench-collapse-dt
bench-collapse-dt: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	for dt in $(COLLAPSE_DTS); do \
	  OMP_NUM_THREADS=2 /usr/bin/python3 bench/collapse_study.py $(BUILD)/muflow $(BENCH_OUT) \
	    $(COLLAPSE_N) solver.dt=$$dt --tag dt$$dt || exit 1; \
	  OMP_NUM_THREADS=2 /usr/bin/python3 bench/collapse_study.py $(BUILD)/muflow $(BENCH_OUT) \
	    $(COLLAPSE_N) $(COLLAPSE_NGF) solver.dt=$$dt --tag ngf_dt$$dt || exit 1; \
	done

# The column released on a bent incline (cases/slope_release.ini) to rest at
# SLOPE_RELEASE_N cells per column height, beside the depth-averaged model:
# run-out, tail, time to rest, volume error per grid
# ($(BENCH_OUT)/slope_release_table.md), the fronts and tails against t
# (slope_release_front.png) and the deposits (slope_release_deposit.png).
# About 15 minutes on 2 idle cores, most of it N = 16.
SLOPE_RELEASE_N ?= 8 12 16
.PHONY: bench-slope-release
bench-slope-release: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/slope_release_study.py $(BUILD)/muflow $(BENCH_OUT) \
	  $(SLOPE_RELEASE_N)

# The collapse beside Gerris 1.3.2 (the code of the published runs; Debian's
# gerris, and libgfs-dev, whose headers Gerris needs to compile a case's
# functions): a = 0.5 to t = 4 at 25.6 and 51.2 cells per H0
# (COLLAPSE_GERRIS_LEVELS 7 8; 9 is 102.4, where Gerris takes many minutes:
# docs/benchmarks.md), the granular
# viscosity clipped at 10 (Gerris's example) and 1e4 (the Basilisk port,
# muflow's published set-up), Gerris's step capped at 0.01 (its example's)
# and 0.02, muflow's at 0.01 (its set-up's) and 0.04, and 0.03 and 0.04 with
# the advective CFL number 1 and the VOF's limit of the step off
# (collapse.vof_cfl = 0); every run of a repeat in one sitting:
# collapse_gerris.md and collapse_gerris_runs.csv in $(BENCH_OUT).  About 25
# minutes on 2 idle cores with the defaults.
COLLAPSE_GERRIS_LEVELS ?= 7 8
COLLAPSE_GERRIS_CAPS ?= 10 1e4
COLLAPSE_GERRIS_GERRIS_DTS ?= 0.01 0.02
COLLAPSE_GERRIS_REPEATS ?= 2
.PHONY: bench-collapse-gerris
bench-collapse-gerris: deps bench-deps $(BUILD)/muflow
	@$(MAKE) --no-print-directory deps DEB_PKGS="gerris libgfs-dev"
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/collapse_gerris.py $(BUILD)/muflow $(BENCH_OUT) \
	  --levels $(COLLAPSE_GERRIS_LEVELS) --caps $(COLLAPSE_GERRIS_CAPS) \
	  --gerris-dts $(COLLAPSE_GERRIS_GERRIS_DTS) \
	  --repeats $(COLLAPSE_GERRIS_REPEATS)

# The collapse's front beside Gerris's with the same model: a = 1.42 to t =
# 6, the harmonic mixture (collapse.mixture = harmonic, Gerris's), the clip
# 10 (Gerris's example), van Leer's advection, each code's own step, at
# 12.8, 25.6, 51.2 cells per H0 (COLLAPSE_FRONT_LEVELS 6 7 8; 9 is 102.4,
# about 13 minutes more): the largest |x_f(muflow) - x_f(Gerris)| over t in
# [0, 6], and each grid of both codes against Gerris's finest,
# collapse_gerris_front.md in $(BENCH_OUT).  About 4 minutes on 2 shared
# cores with the defaults; COLLAPSE_FRONT_ARGS="--advection centred --reuse"
# runs muflow's other advection beside Gerris's runs already there.
COLLAPSE_FRONT_LEVELS ?= 6 7 8
COLLAPSE_FRONT_ARGS ?=
.PHONY: bench-collapse-gerris-front
bench-collapse-gerris-front: deps bench-deps $(BUILD)/muflow
	@$(MAKE) --no-print-directory deps DEB_PKGS="gerris libgfs-dev"
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/collapse_gerris_front.py $(BUILD)/muflow $(BENCH_OUT) \
	  --levels $(COLLAPSE_FRONT_LEVELS) $(COLLAPSE_FRONT_ARGS)

# The ill-posedness of mu(I) as a measured growth rate: cases/bagnold2.ini in
# time from the exact solution plus a perturbation, Barker & Rauter (2018), sec. 3.1 (Table
# 1, 32 degrees, three grids, up to five time steps, lambda 1e-8) and 3.2
# (Table 2, 28.5 degrees, jop and barker_gray, three grids): illposed_table.md,
# illposed_runs.csv, illposed_growth.png into $(BENCH_OUT)/illposed.  About
# 40 minutes on 2 shared cores (a run whose summary.ini exists is kept).
.PHONY: bench-illposed
bench-illposed: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	OMP_NUM_THREADS=2 /usr/bin/python3 bench/illposed_study.py $(BUILD)/muflow $(BENCH_OUT)/illposed

# The implicit step's cost against the grid: 30 steps of the collapse (32,
# 64, 128 cells per H0), the Bingham cavity (64^2 to 256^2, Bn 10 and 1000),
# the granular cylinder (D/8 to D/32) and bagnold2 (50 x 100 to 200 x 400)
# under `auto` and another solver beside it, on one thread: CPU per cell and
# step, peak memory, Krylov iterations a step ($(BENCH_OUT)/scaling.md).
# Grids whose estimate passes SCALING_MEMORY bytes are refused, a row each.
SCALING_STEPS  ?= 30
SCALING_MEMORY ?= 6000000000
.PHONY: bench-scaling
bench-scaling: deps bench-deps $(BUILD)/muflow
	@mkdir -p $(BENCH_OUT)
	MUFLOW_MEMORY_BOUND=$(SCALING_MEMORY) /usr/bin/python3 bench/scaling.py $(BUILD)/muflow \
	  $(BENCH_OUT) --steps $(SCALING_STEPS)

# Pictures of the column collapse: cases/collapse.ini with a field file every
# 0.25 time units to t = 6 (or rest), then tools/collapse_movie.py draws T and
# |u| per field file (PNG) and the animation (GIF through Pillow; also MP4 when
# Debian's ffmpeg is installed) into $(COLLAPSE_PICTURES)/pictures.  About a
# minute on 2 idle cores.
COLLAPSE_PICTURES ?= out/collapse_pictures
.PHONY: collapse-pictures
collapse-pictures: deps $(BUILD)/muflow
	@$(MAKE) --no-print-directory deps DEB_PKGS="python3-matplotlib python3-h5py python3-pil"
	OMP_NUM_THREADS=2 $(BUILD)/muflow cases/collapse.ini output.dir=$(COLLAPSE_PICTURES) \
	  output.fields_interval=0.25 solver.end_time=6 output.quiet=on
	/usr/bin/python3 tools/collapse_movie.py $(COLLAPSE_PICTURES)
