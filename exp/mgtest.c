/* experiment: velocity multigrid on model problems */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "grid/grid.h"
#include "grid/boundary.h"
#include "kernels/kernels.h"
#include "kernels/viscous_stencil.h"
#include "solvers/viscous_operator.h"
#include "solvers/velocity_mg.h"
#include "solvers/gmres.h"

static double now(void){struct timespec t;clock_gettime(CLOCK_MONOTONIC,&t);return t.tv_sec+1e-9*t.tv_nsec;}
static unsigned long long seed=12345;
static double rnd(void){seed=seed*6364136223846793005ULL+1442695040888963407ULL;return (double)(seed>>11)/9007199254740992.0;}

struct ctx { struct grid g; struct boundary bc; struct box act[3]; struct viscous_work w; struct viscous_problem pb; struct velocity_mg *mg; double *f[3], *o[3]; long n; };

static void gather(struct ctx *c, double *f[3], double *v, int to){ long n=0; for(int a=0;a<3;a++){const struct box*b=&c->act[a]; for(int i=b->lo[0];i<b->hi[0];i++)for(int j=b->lo[1];j<b->hi[1];j++)for(int k=b->lo[2];k<b->hi[2];k++,n++){ptrdiff_t p=grid_idx(&c->g,i,j,k); if(to) v[n]=f[a][p]; else f[a][p]=v[n];}}}
static void op(void *ctx,const double*x,double*y){struct ctx*c=ctx; for(int a=0;a<3;a++) memset(c->f[a],0,c->g.size*8); gather(c,c->f,(double*)x,0); viscous_operator_eval(&c->g,&c->bc,c->act,&c->w,&c->pb,c->f,c->o); gather(c,c->o,y,1);}
static void prec(void *ctx,const double*x,double*y){struct ctx*c=ctx; for(int a=0;a<3;a++) memset(c->f[a],0,c->g.size*8); gather(c,c->f,(double*)x,0); velocity_mg_cycle(c->mg,c->f,c->o); gather(c,c->o,y,1);}
static void noprec(void *ctx,const double*x,double*y){struct ctx*c=ctx; memcpy(y,x,c->n*8);}

int main(int argc,char**argv){
  int nx=atoi(argv[1]), nz=atoi(argv[2]); double contrast=argc>3?atof(argv[3]):1; int kind=argc>4?atoi(argv[4]):0; double mass=argc>5?atof(argv[5]):1e-6;
  int ny = argc>6?atoi(argv[6]):1;
  struct ctx c; memset(&c,0,sizeof c);
  int n[3]={nx,ny,nz}; double len[3]={1.0*nx/nz,(double)ny/nz,1};
  grid_init(&c.g,n,len);
  c.bc.face[0][0]=c.bc.face[0][1]=BC_WALL; c.bc.face[1][0]=c.bc.face[1][1]=BC_PERIODIC; c.bc.face[2][0]=BC_WALL; c.bc.face[2][1]=kind&1?BC_SLIP:BC_WALL;
  if(kind&2){c.bc.face[0][0]=c.bc.face[0][1]=BC_PERIODIC;}
  bc_unknown_boxes(&c.g,&c.bc,c.act);
  viscous_work_create(&c.w,&c.g,0);
  double *eta=field_alloc(&c.g), *ee[3]; for(int a=0;a<3;a++) ee[a]=field_alloc(&c.g);
  /* viscosity: a blob of high viscosity (contrast) in a field, or random log-field */
  for(int i=-1;i<=nx;i++)for(int j=-1;j<=ny;j++)for(int k=-1;k<=nz;k++){ double x=(i+0.5)/nz, z=(k+0.5)/nz; double v=1; 
     if(kind&4) v = exp(log(contrast)*rnd()); else if((x-0.5*len[0])*(x-0.5*len[0])+(z-0.4)*(z-0.4)<0.09) v=contrast; eta[grid_idx(&c.g,i,j,k)]=v;}
  for(int a=0;a<3;a++) for(int i=0;i<=nx;i++)for(int j=0;j<=ny;j++)for(int k=-1;k<=nz;k++){ /* edges: mean of 4 cells */ ptrdiff_t p=grid_idx(&c.g,i,j,k); ptrdiff_t o1,o2; int b1=(a+1)%3,b2=(a+2)%3; o1=c.g.stride[b1];o2=c.g.stride[b2]; double s=0; int cnt=0; ptrdiff_t q[4]={p,p-o1,p-o2,p-o1-o2}; for(int t=0;t<4;t++){ if(q[t]>=0 && q[t]<(ptrdiff_t)c.g.size){s+=eta[q[t]];cnt++;}} ee[a][p]= s/cnt; }
  for(int a=0;a<3;a++){c.pb.A_cell[a]=eta; c.pb.A_edge[a]=ee[a];}
  c.pb.mass=mass;
  for(int a=0;a<3;a++){c.f[a]=field_alloc(&c.g); c.o[a]=field_alloc(&c.g);}
  /* check the stencil against the operator at random nodes */
  { struct own_stencil st[3]; for(int a=0;a<3;a++){st[a].diag=field_alloc(&c.g); for(int d=0;d<3;d++){st[a].cp[d]=field_alloc(&c.g);st[a].cm[d]=field_alloc(&c.g);} struct stencil_coefficients k={.mass=mass}; for(int e=0;e<3;e++){k.A_cell[e]=eta;k.A_edge[e]=ee[e];} kernel_own_stencil(&c.g,&c.bc,&c.act[a],a,&k,&st[a]);}
    double maxerr=0; for(int t=0;t<200;t++){ int a=t%3; const struct box*b=&c.act[a]; if(b->hi[0]<=b->lo[0]||b->hi[1]<=b->lo[1]||b->hi[2]<=b->lo[2]) continue; int idx[3]; for(int d=0;d<3;d++) idx[d]=b->lo[d]+(int)(rnd()*(b->hi[d]-b->lo[d])); if(t<6){ for(int d=0;d<3;d++) idx[d]= (t&1)? b->lo[d]: b->hi[d]-1;}
      for(int e=0;e<3;e++) memset(c.f[e],0,c.g.size*8); ptrdiff_t p=grid_idx(&c.g,idx[0],idx[1],idx[2]); c.f[a][p]=1; viscous_operator_eval(&c.g,&c.bc,c.act,&c.w,&c.pb,c.f,c.o);
      double e1=fabs(c.o[a][p]-st[a].diag[p])/st[a].diag[p]; if(e1>maxerr){maxerr=e1;}
      for(int d=0;d<3;d++){ for(int s=-1;s<=1;s+=2){ int q[3]={idx[0],idx[1],idx[2]}; q[d]+=s; if(c.bc.face[d][0]==BC_PERIODIC){ if(q[d]<0)q[d]+=c.g.n[d]; if(q[d]>=c.g.n[d]) q[d]-=c.g.n[d]; if(q[d]==idx[d]) continue;} if(q[d]<b->lo[d]||q[d]>=b->hi[d]) continue; ptrdiff_t pq=grid_idx(&c.g,q[0],q[1],q[2]); double cc = s>0? st[a].cp[d][pq - (ptrdiff_t)s*c.g.stride[d]]:0; (void)cc; 
        /* column p response at row pq equals -(coupling of row pq to p) */ double coup = s>0 ? st[a].cm[d][pq] : st[a].cp[d][pq]; if(c.g.n[d]==2 && c.bc.face[d][0]==BC_PERIODIC) coup = st[a].cm[d][pq]+st[a].cp[d][pq];
        double e2=fabs(-c.o[a][pq]-coup)/st[a].diag[p]; if(e2>maxerr) {maxerr=e2; printf("coupling mismatch a=%d d=%d s=%d at %d %d %d: op %g stencil %g\n",a,d,s,idx[0],idx[1],idx[2],-c.o[a][pq],coup);} } } }
    printf("stencil check: max relative error %.3e\n",maxerr); }
  char err[256]; struct velocity_mg_options o; velocity_mg_default_options(&o); if(getenv("MG_PRE")) o.pre=o.post=atoi(getenv("MG_PRE")); if(getenv("MG_GAMMA")) o.gamma=atoi(getenv("MG_GAMMA")); if(getenv("MG_COARSE")) o.coarse_cells=atol(getenv("MG_COARSE"));
  if(velocity_mg_create(&c.mg,&c.g,&c.bc,c.act,&o,err,sizeof err)){printf("create: %s\n",err);return 1;}
  double t0=now(); if(velocity_mg_setup(c.mg,&c.pb,err,sizeof err)){printf("setup: %s\n",err);return 1;} double t1=now();
  c.n=0; for(int a=0;a<3;a++){const struct box*b=&c.act[a]; c.n+=(long)(b->hi[0]-b->lo[0])*(b->hi[1]-b->lo[1])*(b->hi[2]-b->lo[2]);}
  double *bv=malloc(c.n*8),*xv=calloc(c.n,8); for(long i=0;i<c.n;i++) bv[i]=rnd()-0.5;
  struct gmres *gm; gmres_create(&gm,c.n,30); struct gmres_stats gs; 
  int rc=gmres_solve(gm,op,getenv("NOPREC")?noprec:prec,&c,bv,xv,1e-8,300,&gs); double t2=now();
  printf("grid %d x %d x %d contrast %g kind %d levels %d: rc %d iterations %d rel %.2e setup %.3f s solve %.3f s\n",nx,ny,nz,contrast,kind,velocity_mg_levels(c.mg),rc,gs.iterations,gs.relative_residual,t1-t0,t2-t1);
  return 0; }
