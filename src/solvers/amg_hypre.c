/* BoomerAMG on the probed matrix (amg_hypre.h).  The only file that talks to
 * hypre and MPI, which it loads with dlopen when the first AMG is created. */
#define _DEFAULT_SOURCE /* ffs() in hypre's internal headers */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <dlfcn.h>
#include <omp.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <mpi.h>
#include <HYPRE.h>
#include <HYPRE_parcsr_ls.h>
/* hypre's internal headers, for the vectors' data and the hierarchy's sizes;
 * they are not -Wextra clean */
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include <_hypre_parcsr_ls.h>
#pragma GCC diagnostic pop
#include "solvers/amg_hypre.h"
#include "platform/blas.h"
#include "platform/dynlib.h"

_Static_assert(sizeof(HYPRE_Int) == sizeof(int), "hypre built with 32-bit indices expected");
_Static_assert(sizeof(HYPRE_Real) == sizeof(double), "hypre built in double precision expected");

/* One diagonal block of the matrix: the unknowns first .. first + n - 1 (whole
 * velocity components), with its own matrix, vectors and hierarchy. */
struct amg_block {
    int first, n;
    int ncomp;                  /* velocity components in the block */
    /* a communicator of its own (a copy of MPI_COMM_SELF): hypre's set-up
     * and its coarsest level's direct solve call collectives, and MPI allows
     * those from several threads at once only on different communicators */
    MPI_Comm comm;
    int has_comm;
    HYPRE_IJMatrix ij;
    HYPRE_ParCSRMatrix A;
    HYPRE_IJVector ijb, ijx;
    HYPRE_ParVector b, x;
    HYPRE_Solver amg;
    int rc;                     /* of its last set-up */
    int built;                  /* its hierarchy is set up (amg_hypre_prepare) */
    int dropped;                /* the last amg_hypre_prepare left it out */
};

struct amg_hypre {
    int n;
    int *dof_func;
    int *rows, *ncols;          /* 0 .. n-1 and the entries of each row */
    int *zeros;                 /* n zeros: no row has entries off this rank */
    struct amg_options o;
    int nblocks;                /* 0 before the first set-up */
    struct amg_block blk[3];
    int levels;
    double complexity;
};

/* ---- hypre and MPI, loaded on first use ---------------------------------- */

/* The library is opened when the first AMG is created, not linked: linked,
 * hypre and OpenMPI would slow every program start although only
 * solver.preconditioner = amg uses them
 * (docs/numerics/threads-and-platform.md).  Its
 * soname comes from the -dev package's libHYPRE.so link (Makefile); the
 * headers still give the types and prototypes, and each pointer below is
 * declared with its function's own type (__typeof__), so a prototype that
 * changes with the headers changes the pointer with it.  RTLD_GLOBAL: hypre's
 * OpenMPI comes along and its plugins see libmpi's symbols. */
#ifndef MUFLOW_HYPRE_LIB
#define MUFLOW_HYPRE_LIB "libHYPRE-2.26.0.so"
#endif

#define HYPRE_FUNCTIONS(X)                                                                        \
    X(HYPRE_Init) X(HYPRE_Finalize) X(HYPRE_ClearAllErrors)                                       \
    X(HYPRE_IJMatrixCreate) X(HYPRE_IJMatrixSetObjectType) X(HYPRE_IJMatrixSetDiagOffdSizes)      \
    X(HYPRE_IJMatrixInitialize) X(HYPRE_IJMatrixSetValues) X(HYPRE_IJMatrixAssemble)              \
    X(HYPRE_IJMatrixGetObject) X(HYPRE_IJMatrixDestroy)                                           \
    X(HYPRE_IJVectorCreate) X(HYPRE_IJVectorSetObjectType) X(HYPRE_IJVectorInitialize)            \
    X(HYPRE_IJVectorAssemble) X(HYPRE_IJVectorGetObject) X(HYPRE_IJVectorDestroy)                 \
    X(HYPRE_BoomerAMGCreate) X(HYPRE_BoomerAMGDestroy) X(HYPRE_BoomerAMGSetup)                    \
    X(HYPRE_BoomerAMGSolve) X(HYPRE_BoomerAMGSetPrintLevel) X(HYPRE_BoomerAMGSetMaxIter)          \
    X(HYPRE_BoomerAMGSetTol) X(HYPRE_BoomerAMGSetCoarsenType) X(HYPRE_BoomerAMGSetInterpType)     \
    X(HYPRE_BoomerAMGSetPMaxElmts) X(HYPRE_BoomerAMGSetStrongThreshold)                          \
    X(HYPRE_BoomerAMGSetMaxRowSum) X(HYPRE_BoomerAMGSetRelaxType) X(HYPRE_BoomerAMGSetNumSweeps)  \
    X(HYPRE_BoomerAMGSetAggNumLevels) X(HYPRE_BoomerAMGSetNumFunctions)                          \
    X(HYPRE_BoomerAMGSetDofFunc) X(HYPRE_BoomerAMGSetCycleNumSweeps)                             \
    X(MPI_Init_thread) X(MPI_Query_thread) X(MPI_Initialized) X(MPI_Finalize) X(MPI_Finalized)   \
    X(MPI_Comm_dup) X(MPI_Comm_free)

static struct {
    void *lib;
#define POINTER(f) __typeof__(f) *f;
    HYPRE_FUNCTIONS(POINTER)
#undef POINTER
    MPI_Comm comm_self; /* MPI_COMM_SELF, an address in libmpi */
} hy;

/* OpenMPI's MPI_COMM_SELF is the address of this object */
#define COMM_SELF_SYMBOL "ompi_mpi_comm_self"
_Static_assert(sizeof(MPI_Comm) == sizeof(void *), "OpenMPI's MPI_Comm, a pointer, expected");

static int load_hypre(char *err, size_t errlen)
{
    if (hy.lib)
        return 0;
    /* MUFLOW_HYPRE_LIB names another file (tests: a missing library) */
    const char *name = getenv("MUFLOW_HYPRE_LIB");
    if (!name || !*name)
        name = MUFLOW_HYPRE_LIB;
    blas_prepare(); /* hypre's BLAS and LAPACK: the serial build */
    void *lib = dynlib_open(name, RTLD_GLOBAL, "solver.preconditioner = amg needs hypre's library",
                            "libhypre-dev", err, errlen);
    if (!lib)
        return -1;
    const char *missing = NULL;
    void *p;
#define RESOLVE(f) DYNLIB_RESOLVE(lib, hy, f, missing)
    HYPRE_FUNCTIONS(RESOLVE)
#undef RESOLVE
    if (!missing) {
        p = dlsym(lib, COMM_SELF_SYMBOL);
        if (p)
            hy.comm_self = (MPI_Comm)p;
        else
            missing = COMM_SELF_SYMBOL;
    }
    if (missing) {
        snprintf(err, errlen,
                 "solver.preconditioner = amg: hypre's library %s (or its MPI) lacks %s", name,
                 missing);
        dlclose(lib);
        memset(&hy, 0, sizeof hy);
        return -1;
    }
    hy.lib = lib; /* kept open: MPI is finalised at exit */
    return 0;
}

int amg_hypre_available(char *err, size_t errlen)
{
    return load_hypre(err, errlen) == 0;
}

static int hypre_started;
static int hypre_threads; /* MPI allows calls from several threads at once */

static void finish_at_exit(void)
{
    hy.HYPRE_Finalize();
    int done = 0;
    hy.MPI_Finalized(&done);
    if (!done)
        hy.MPI_Finalize();
}

/* A serial program gets a one-rank MPI (MPI_COMM_SELF is what hypre sees). */
static int start_hypre(char *err, size_t errlen)
{
    if (hypre_started)
        return 0;
    if (load_hypre(err, errlen) != 0)
        return -1;
    int init = 0, provided = MPI_THREAD_SINGLE;
    hy.MPI_Initialized(&init);
    int own = !init;
    /* the blocks' hierarchies are set up and applied on threads of their own
     * (amg_hypre_setup), and hypre talks to MPI (on MPI_COMM_SELF) in both */
    if (own && hy.MPI_Init_thread(NULL, NULL, MPI_THREAD_MULTIPLE, &provided) != MPI_SUCCESS) {
        snprintf(err, errlen, "amg: MPI_Init_thread failed");
        return -1;
    }
    if (!own)
        hy.MPI_Query_thread(&provided);
    hypre_threads = provided >= MPI_THREAD_MULTIPLE;
    hy.HYPRE_Init();
#ifdef __GLIBC__
    mallopt(M_MMAP_THRESHOLD, 128 * 1024);
#endif
    if (own)
        atexit(finish_at_exit);
    hypre_started = 1;
    return 0;
}

/* ---- options --------------------------------------------------------------- */

void amg_options_default(struct amg_options *o)
{
    *o = (struct amg_options){.coarsen = 10, .interp = 6, .theta = 0.5, .relax = 8, .sweeps = 1,
                              .pre_sweeps = 0,
                              .systems = 1, .agg_levels = 0, .pmax = 4, .max_row_sum = 0.9,
                              .print = 0};
}

struct named {
    const char *name;
    int code;
};
static const struct named coarsen_names[] = {
    {"hmis", 10}, {"pmis", 8}, {"falgout", 6}, {"cljp", 0}, {NULL, 0}};
static const struct named interp_names[] = {
    {"ext+i", 6}, {"classical", 0}, {"ff1", 13}, {"ext", 14}, {"direct", 3}, {NULL, 0}};
static const struct named relax_names[] = {
    {"l1gs", 8}, {"hsgs", 6}, {"hgs", 3}, {"l1jacobi", 18}, {"jacobi", 0}, {NULL, 0}};

static int lookup(const struct named *t, const char *v, int *code)
{
    for (; t->name; t++)
        if (strcmp(t->name, v) == 0) {
            *code = t->code;
            return 0;
        }
    char *end;
    long x = strtol(v, &end, 10);
    if (*v && !*end) {
        *code = (int)x;
        return 0;
    }
    return -1;
}

static const char *name_of(const struct named *t, int code)
{
    for (; t->name; t++)
        if (t->code == code)
            return t->name;
    return "?";
}

int amg_options_parse(struct amg_options *o, const char *spec, char *err, size_t errlen)
{
    if (!spec)
        return 0;
    char buf[512];
    snprintf(buf, sizeof buf, "%s", spec);
    for (char *save = NULL, *tok = strtok_r(buf, ",", &save); tok;
         tok = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(tok, '=');
        if (!eq) {
            snprintf(err, errlen, "amg option '%s': key=value expected", tok);
            return -1;
        }
        *eq = '\0';
        const char *k = tok, *v = eq + 1;
        int bad = 0;
        if (strcmp(k, "coarsen") == 0)
            bad = lookup(coarsen_names, v, &o->coarsen);
        else if (strcmp(k, "interp") == 0)
            bad = lookup(interp_names, v, &o->interp);
        else if (strcmp(k, "relax") == 0)
            bad = lookup(relax_names, v, &o->relax);
        else if (strcmp(k, "theta") == 0)
            o->theta = atof(v);
        else if (strcmp(k, "rowsum") == 0)
            o->max_row_sum = atof(v);
        else if (strcmp(k, "sweeps") == 0)
            o->sweeps = atoi(v);
        else if (strcmp(k, "pre") == 0) {
            char *end;
            long x = strtol(v, &end, 10);
            if (!*v || *end || x < 0 || x > 10) {
                snprintf(err, errlen, "amg option pre=%s: an integer in [0, 10]", v);
                return -1;
            }
            o->pre_sweeps = (int)x;
        }
        else if (strcmp(k, "systems") == 0)
            o->systems = atoi(v);
        else if (strcmp(k, "agg") == 0)
            o->agg_levels = atoi(v);
        else if (strcmp(k, "pmax") == 0)
            o->pmax = atoi(v);
        else if (strcmp(k, "print") == 0)
            o->print = atoi(v);
        else
            bad = 1;
        if (bad) {
            snprintf(err, errlen, "amg option %s=%s: unknown", k, v);
            return -1;
        }
    }
    return 0;
}

void amg_options_describe(const struct amg_options *o, char *buf, size_t len)
{
    snprintf(buf, len, "%s %s(%d) theta %g %s V(%d,%d)%s%s", name_of(coarsen_names, o->coarsen),
             name_of(interp_names, o->interp), o->pmax, o->theta, name_of(relax_names, o->relax),
             o->pre_sweeps, o->sweeps, o->systems ? " systems" : "", o->agg_levels ? " agg" : "");
}

/* ---- the preconditioner ---------------------------------------------------- */

/* Couplings between velocity components below this share of their
 * diagonals' geometric mean are round-off (component_blocks). */
#define COUPLING_ROUNDOFF 1e-12

int amg_hypre_create(struct amg_hypre **out, int n, const int *dof_func,
                     const struct amg_options *o, char *err, size_t errlen)
{
    if (start_hypre(err, errlen) != 0)
        return -1;
    struct amg_hypre *a = calloc(1, sizeof *a);
    if (!a) {
        snprintf(err, errlen, "amg: out of memory");
        return -1;
    }
    a->n = n;
    a->o = *o;
    a->dof_func = malloc((size_t)n * sizeof(int));
    a->rows = malloc((size_t)n * sizeof(int));
    a->ncols = malloc((size_t)n * sizeof(int));
    a->zeros = calloc((size_t)n, sizeof(int));
    if (!a->dof_func || !a->rows || !a->ncols || !a->zeros) {
        amg_hypre_destroy(a);
        snprintf(err, errlen, "amg: out of memory");
        return -1;
    }
    memcpy(a->dof_func, dof_func, (size_t)n * sizeof(int));
    for (int r = 0; r < n; r++)
        a->rows[r] = r;
    *out = a;
    return 0;
}

static void release_hierarchy(struct amg_hypre *a)
{
    for (int k = 0; k < a->nblocks; k++) {
        struct amg_block *b = &a->blk[k];
        if (b->amg)
            hy.HYPRE_BoomerAMGDestroy(b->amg);
        if (b->ij)
            hy.HYPRE_IJMatrixDestroy(b->ij);
        b->amg = NULL;
        b->ij = NULL;
        b->A = NULL;
        b->built = b->dropped = 0;
    }
}

void amg_hypre_release(struct amg_hypre *a)
{
    if (a)
        release_hierarchy(a);
}

static void destroy_blocks(struct amg_hypre *a)
{
    release_hierarchy(a);
    for (int k = 0; k < a->nblocks; k++) {
        if (a->blk[k].ijb)
            hy.HYPRE_IJVectorDestroy(a->blk[k].ijb);
        if (a->blk[k].ijx)
            hy.HYPRE_IJVectorDestroy(a->blk[k].ijx);
        if (a->blk[k].has_comm)
            hy.MPI_Comm_free(&a->blk[k].comm);
    }
    memset(a->blk, 0, sizeof a->blk);
    a->nblocks = 0;
}

void amg_hypre_destroy(struct amg_hypre *a)
{
    if (!a)
        return;
    destroy_blocks(a);
    free(a->dof_func);
    free(a->rows);
    free(a->ncols);
    free(a->zeros);
    free(a);
}

static double *vector_data(HYPRE_ParVector v)
{
    return hypre_VectorData(hypre_ParVectorLocalVector((hypre_ParVector *)v));
}

static long parcsr_entries(hypre_ParCSRMatrix *A)
{
    hypre_CSRMatrix *d = hypre_ParCSRMatrixDiag(A), *o = hypre_ParCSRMatrixOffd(A);
    return (long)hypre_CSRMatrixNumNonzeros(d) + (o ? hypre_CSRMatrixNumNonzeros(o) : 0);
}

/* The velocity components that M couples, split into diagonal blocks of
 * whole components: first[k] .. first[k+1] - 1 are block k's unknowns.  The
 * unknowns come component by component (probe_matrix.h), so a block is a
 * range of consecutive components, and components c and c + 1 start
 * separate blocks when no entry couples any component up to c with any
 * after it.  A flow along one direction only (the heap, the profiles and
 * ducts at rest across) has no entry between its velocity component and the
 * two across, in the tangent as in the Picard operator: two blocks. */
static int component_blocks(const struct amg_hypre *a, const struct csr_matrix *M, int first[4])
{
    int start[4], coupled[3][3] = {{0}};
    for (int c = 0, r = 0; c <= 3; c++) {
        while (r < a->n && a->dof_func[r] < c)
            r++;
        start[c] = r;
    }
    for (int r = 1; r < a->n; r++)
        if (a->dof_func[r] < a->dof_func[r - 1]) { /* not by component: one block */
            first[0] = 0, first[1] = a->n;
            return 1;
        }
    /* a coupling counts above round-off of its row's and column's diagonal
     * (the tangent of a flow along one direction holds the state's
     * round-off across it); the V-cycles drop those below, GMRES keeps them
     * in the operator */
    double *diag = malloc((size_t)a->n * sizeof(double));
    if (!diag) {
        first[0] = 0, first[1] = a->n;
        return 1;
    }
    for (int r = 0; r < a->n; r++) {
        diag[r] = 0.0;
        for (int e = M->rowptr[r]; e < M->rowptr[r + 1]; e++)
            if (M->col[e] == r)
                diag[r] = fabs(M->val[e]);
    }
    for (int r = 0; r < a->n; r++)
        for (int e = M->rowptr[r]; e < M->rowptr[r + 1]; e++) {
            int c = M->col[e];
            if (a->dof_func[c] != a->dof_func[r] &&
                fabs(M->val[e]) > COUPLING_ROUNDOFF * sqrt(diag[r] * diag[c]))
                coupled[a->dof_func[r]][a->dof_func[c]] = 1;
        }
    free(diag);
    int nb = 0;
    first[0] = 0;
    for (int c = 0; c < 2; c++) {
        int apart = 1;
        for (int i = 0; i <= c; i++)
            for (int j = c + 1; j < 3; j++)
                apart &= !coupled[i][j] && !coupled[j][i];
        /* a component without unknowns starts no block */
        if (apart && start[c + 1] > first[nb] && start[c + 1] < a->n)
            first[++nb] = start[c + 1];
    }
    first[++nb] = a->n;
    return nb;
}

/* M's rows, each keeping the entries of its own block with columns
 * numbered from the block's first unknown (hypre numbers each block from 0:
 * its direct solve of the coarsest level gathers rows by their numbers), in
 * place; ncols the entries kept a row. */
static void split_rows(struct amg_hypre *a, struct csr_matrix *M, int nb, const int first[4])
{
    int w = 0;
    for (int k = 0; k < nb; k++)
        for (int r = first[k]; r < first[k + 1]; r++) {
            int e0 = M->rowptr[r], e1 = M->rowptr[r + 1];
            M->rowptr[r] = w;
            for (int e = e0; e < e1; e++)
                if (M->col[e] >= first[k] && M->col[e] < first[k + 1]) {
                    M->col[w] = M->col[e] - first[k];
                    M->val[w++] = M->val[e];
                }
            a->ncols[r] = w - M->rowptr[r];
        }
    M->rowptr[a->n] = w;
}

/* The blocks' vectors for the layout first[0 .. nb]: kept while it holds. */
static int layout_blocks(struct amg_hypre *a, int nb, const int first[4])
{
    int same = nb == a->nblocks;
    for (int k = 0; same && k < nb; k++)
        same = a->blk[k].first == first[k] && a->blk[k].n == first[k + 1] - first[k];
    if (same)
        return 0;
    destroy_blocks(a);
    a->nblocks = nb;
    for (int k = 0; k < nb; k++) {
        struct amg_block *b = &a->blk[k];
        b->first = first[k];
        b->n = first[k + 1] - first[k];
        b->ncomp = a->dof_func[first[k + 1] - 1] - a->dof_func[first[k]] + 1;
        if (hy.MPI_Comm_dup(hy.comm_self, &b->comm) != MPI_SUCCESS)
            return -1;
        b->has_comm = 1;
        HYPRE_IJVector *v[2] = {&b->ijb, &b->ijx};
        HYPRE_ParVector *pv[2] = {&b->b, &b->x};
        for (int m = 0; m < 2; m++) {
            if (hy.HYPRE_IJVectorCreate(b->comm, 0, b->n - 1, v[m]) != 0)
                return -1;
            hy.HYPRE_IJVectorSetObjectType(*v[m], HYPRE_PARCSR);
            hy.HYPRE_IJVectorInitialize(*v[m]);
            hy.HYPRE_IJVectorAssemble(*v[m]);
            void *obj;
            hy.HYPRE_IJVectorGetObject(*v[m], &obj);
            *pv[m] = obj;
        }
    }
    return 0;
}

/* Block b's rows of M (split_rows) into hypre's matrix (hypre copies them). */
static int load_block(struct amg_hypre *a, struct amg_block *b, const struct csr_matrix *M)
{
    int f = b->first, last = b->n - 1;
    hy.HYPRE_IJMatrixCreate(b->comm, 0, last, 0, last, &b->ij);
    hy.HYPRE_IJMatrixSetObjectType(b->ij, HYPRE_PARCSR);
    /* exact row sizes of the local block (one rank: every column local) let
     * hypre write the values into its matrix directly, without the
     * auxiliary row arrays it otherwise fills and converts on assembly (a
     * third copy of the matrix at the peak) */
    hy.HYPRE_IJMatrixSetDiagOffdSizes(b->ij, a->ncols + f, a->zeros + f);
    hy.HYPRE_IJMatrixInitialize(b->ij);
    hy.HYPRE_IJMatrixSetValues(b->ij, b->n, a->ncols + f, a->rows, M->col + M->rowptr[f],
                               M->val + M->rowptr[f]);
    if (hy.HYPRE_IJMatrixAssemble(b->ij) != 0)
        return -1;
    void *obj;
    hy.HYPRE_IJMatrixGetObject(b->ij, &obj);
    b->A = obj;
    return 0;
}

/* Block b's hierarchy. */
static int build_block(const struct amg_hypre *a, struct amg_block *b)
{
    const struct amg_options *o = &a->o;
    hy.HYPRE_BoomerAMGCreate(&b->amg);
    hy.HYPRE_BoomerAMGSetPrintLevel(b->amg, o->print ? 1 : 0);
    hy.HYPRE_BoomerAMGSetMaxIter(b->amg, 1);
    hy.HYPRE_BoomerAMGSetTol(b->amg, 0.0);
    hy.HYPRE_BoomerAMGSetCoarsenType(b->amg, o->coarsen);
    hy.HYPRE_BoomerAMGSetInterpType(b->amg, o->interp);
    hy.HYPRE_BoomerAMGSetPMaxElmts(b->amg, o->pmax);
    hy.HYPRE_BoomerAMGSetStrongThreshold(b->amg, o->theta);
    hy.HYPRE_BoomerAMGSetMaxRowSum(b->amg, o->max_row_sum);
    hy.HYPRE_BoomerAMGSetRelaxType(b->amg, o->relax);
    hy.HYPRE_BoomerAMGSetNumSweeps(b->amg, o->sweeps);
    hy.HYPRE_BoomerAMGSetCycleNumSweeps(b->amg, o->pre_sweeps, 1); /* 1: the down cycle */
    hy.HYPRE_BoomerAMGSetAggNumLevels(b->amg, o->agg_levels);
    if (o->systems && b->ncomp > 1) {
        int *f = malloc((size_t)b->n * sizeof(int)); /* hypre takes and frees it */
        if (!f)
            return -1;
        int c0 = a->dof_func[b->first]; /* hypre's functions count from 0 */
        for (int r = 0; r < b->n; r++)
            f[r] = a->dof_func[b->first + r] - c0;
        hy.HYPRE_BoomerAMGSetNumFunctions(b->amg, b->ncomp);
        hy.HYPRE_BoomerAMGSetDofFunc(b->amg, f);
    }
    memset(vector_data(b->x), 0, (size_t)b->n * sizeof(double));
    return hy.HYPRE_BoomerAMGSetup(b->amg, b->A, b->b, b->x) != 0 ? -1 : 0;
}

/* Threads for the blocks: one each, when MPI allows calls from several. */
static int block_threads(const struct amg_hypre *a)
{
    int t = omp_get_max_threads();
    return hypre_threads && a->nblocks > 1 ? (t < a->nblocks ? t : a->nblocks) : 1;
}

int amg_hypre_setup(struct amg_hypre *a, struct csr_matrix *M)
{
    release_hierarchy(a);
    int n = a->n;
    if (M->n != n)
        return -1;
    int first[4];
    int nb = component_blocks(a, M, first);
    split_rows(a, M, nb, first);
    if (layout_blocks(a, nb, first) != 0)
        return -1;
    int ok = 1;
    for (int k = 0; k < nb; k++)
        ok &= load_block(a, &a->blk[k], M) == 0;
    csr_free(M); /* hypre holds the copies it needs */
    return ok ? 0 : -1;
}

/* Levels and operator complexity of the hierarchies built so far. */
static void hierarchy_stats(struct amg_hypre *a)
{
    long fine = 0, all = 0;
    a->levels = 0;
    for (int k = 0; k < a->nblocks; k++) {
        if (!a->blk[k].built)
            continue;
        hypre_ParAMGData *d = (hypre_ParAMGData *)a->blk[k].amg;
        int levels = hypre_ParAMGDataNumLevels(d);
        hypre_ParCSRMatrix **As = hypre_ParAMGDataAArray(d);
        fine += parcsr_entries(As[0]);
        for (int l = 0; l < levels; l++)
            all += parcsr_entries(As[l]);
        a->levels = levels > a->levels ? levels : a->levels;
    }
    a->complexity = fine > 0 ? (double)all / (double)fine : 0.0;
}

int amg_hypre_prepare(struct amg_hypre *a, const double *b, double negligible)
{
    int todo[3], nt = 0;
    for (int k = 0; k < a->nblocks; k++) {
        struct amg_block *bk = &a->blk[k];
        double bn = csr_vector_norm(b + bk->first, bk->n);
        bk->dropped = a->nblocks > 1 && bn <= negligible;
        if (!bk->dropped && !bk->built && bn > 0.0)
            todo[nt++] = k;
    }
    /* hypre (Debian's build) has no threads of its own: the blocks' set-ups
     * run side by side, each on its own communicator (hypre's error flag is
     * shared: either may set it, and it is cleared after) */
#pragma omp parallel for num_threads(nt > 1 ? block_threads(a) : 1) schedule(dynamic, 1)
    for (int t = 0; t < nt; t++)
        a->blk[todo[t]].rc = build_block(a, &a->blk[todo[t]]);
    hy.HYPRE_ClearAllErrors();
    int ok = 1;
    for (int t = 0; t < nt; t++) {
        a->blk[todo[t]].built = a->blk[todo[t]].rc == 0;
        ok &= a->blk[todo[t]].built;
    }
    hierarchy_stats(a);
    return ok ? 0 : -1;
}

void amg_hypre_apply(struct amg_hypre *a, const double *b, double *x)
{
#pragma omp parallel for num_threads(block_threads(a)) schedule(dynamic, 1)
    for (int k = 0; k < a->nblocks; k++) {
        struct amg_block *bk = &a->blk[k];
        if (!bk->dropped && !bk->built && csr_vector_norm(b + bk->first, bk->n) > 0.0) {
            /* reached only now: built here (its part of x 0 if that fails) */
            bk->rc = build_block(a, bk);
            bk->built = bk->rc == 0;
        }
        if (bk->dropped || !bk->built) {
            memset(x + bk->first, 0, (size_t)bk->n * sizeof(double));
            continue;
        }
        memcpy(vector_data(bk->b), b + bk->first, (size_t)bk->n * sizeof(double));
        memset(vector_data(bk->x), 0, (size_t)bk->n * sizeof(double));
        hy.HYPRE_BoomerAMGSolve(bk->amg, bk->A, bk->b, bk->x);
        memcpy(x + bk->first, vector_data(bk->x), (size_t)bk->n * sizeof(double));
    }
    hy.HYPRE_ClearAllErrors(); /* "not converged" after its one cycle is expected */
}

int amg_hypre_blocks(const struct amg_hypre *a) { return a->nblocks; }

int amg_hypre_dropped(const struct amg_hypre *a)
{
    int n = 0;
    for (int k = 0; k < a->nblocks; k++)
        n += a->blk[k].dropped;
    return n;
}

int amg_hypre_dropped_components(const struct amg_hypre *a)
{
    int m = 0;
    for (int k = 0; k < a->nblocks; k++)
        if (a->blk[k].dropped) /* a range of whole components */
            for (int c = a->dof_func[a->blk[k].first];
                 c <= a->dof_func[a->blk[k].first + a->blk[k].n - 1]; c++)
                m |= 1 << c;
    return m;
}

/* The library with OpenMPI initialised, and the matrix with its hierarchy
 * per unknown: fitted to the heap's peak RSS with amg against lu
 * (docs/numerics/memory-estimate.md). */
#define AMG_LIBRARY_BYTES 12e6
#define AMG_BYTES_PER_UNKNOWN 2000.0

double amg_hypre_memory_estimate(long unknowns)
{
    /* hypre's matrix, its hierarchy (operator complexity 2.5) and the probed
     * rows copied into it, per unknown, and the library with OpenMPI */
    return AMG_LIBRARY_BYTES + AMG_BYTES_PER_UNKNOWN * (double)(unknowns > 0 ? unknowns : 0);
}

int amg_hypre_levels(const struct amg_hypre *a) { return a->levels; }
double amg_hypre_complexity(const struct amg_hypre *a) { return a->complexity; }
