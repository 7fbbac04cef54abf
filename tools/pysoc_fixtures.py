"""The fixtures of plantwide's self-optimizing-control tests (crates/soc/tests/data/), from pySOC.

Source: github.com/feslima/pySOC at d00877b68ce0e6c98b40c86a9b22d92c43898ca1 (Apache-2.0), its MATLAB
test files (`pysoc/tests/soc/mat_files/...` for the Newell-Lee evaporator, `pysoc/tests/bnb/mat_files/...`
for Yi Cao's 40-measurement random case and his PB3 results). Extract them first:

    git --git-dir=MIRROR archive d00877b pysoc/tests | tar -x -C /tmp/pysoc_fix

then `python3 tools/pysoc_fixtures.py` (numpy, scipy, mpmath). It writes the raw extraction to SCRATCH
and the files the tests read:

- evaporator.json, cao_ny40_nu15_nd5.json: the matrices in `plantwide select --matrices` form;
- evaporator_pysoc.json: every row pySOC's tests compare (helm ss2, hen ss2 and ss3), each with its
  60-digit recomputation from the same doubles and whether the fixture agrees with it to 1e-8;
- evaporator_mp60_best.json: the exact local method's 10 best subsets of each size 2-10, by worst
  case and by average, recomputed at 60 digits (an independent computation, not a pySOC fixture);
- cao_ny40_nu15_nd5_pb3.json: the PB3 results (K = 100 for n = 15, 20, 25).

The losses follow Alstad, Skogestad & Hori (2009), eq. 31 and 41; the fixtures' average is
||M||_F^2 / (6 (n + nd)) (Kariwala et al. 2008, eq. 11).
"""
import os
import numpy as np, json, mpmath as mp, itertools, glob, re
from scipy.io import loadmat
from scipy.linalg import sqrtm
mp.mp.dps = 60
R = '/tmp/pysoc_fix/pysoc/tests/'
COMMIT = 'd00877b68ce0e6c98b40c86a9b22d92c43898ca1'
OUT = '/tmp/pysoc_scratch/'  # SCRATCH: the raw extraction
os.makedirs(OUT, exist_ok=True)
L = lambda A: np.asarray(A, dtype=float).tolist()

# ---------------- evaporator ----------------
a = loadmat(R + 'soc/mat_files/input/helm_hen_input.mat')
b = loadmat(R + 'soc/mat_files/input/matrices_self_opt_100pts.mat')
Gy, Gyd, Juu, Jud = a['Gy'], a['Gyd'], a['Juu'], a['Jud']
md = a['md'].ravel(); me = a['me'].ravel()
assert np.array_equal(np.diag(b['Wd']), md) and np.array_equal(np.diag(b['Wny']), me)
ny, nu = Gy.shape; nd = Gyd.shape[1]

mJ = mp.matrix(Juu.tolist()); mJd = mp.matrix(Jud.tolist())
E, V = mp.eigsy(mJ); S = V * mp.diag([mp.sqrt(e) for e in E]) * V.T; Sinv = mp.inverse(S)
mGy = mp.matrix(Gy.tolist()); mGyd = mp.matrix(Gyd.tolist())
mF = mGyd - mGy * (mp.inverse(mJ) * mJd)      # F = Gyd - Gy Juu^-1 Jud
def rows(Mx, ix, nc): return mp.matrix([[Mx[i, j] for j in range(nc)] for i in ix])
def hcat(A, B):
    C = mp.matrix(A.rows, A.cols + B.cols)
    for r in range(A.rows):
        for c in range(A.cols): C[r, c] = A[r, c]
        for c in range(B.cols): C[r, A.cols + c] = B[r, c]
    return C
def Ftilde(ix):
    return hcat(rows(mF, ix, nd) * mp.diag(md.tolist()), mp.diag([me[i] for i in ix]))
def losses_from_M(M, n):
    s = mp.svd_r(M, compute_uv=False)
    fro2 = sum(x**2 for x in s)
    return dict(worst=float(mp.mpf(1)/2*max(s)**2), avg_uniform=float(fro2/(6*(n+nd))), half_fro2=float(fro2/2))
def exact_local(ix):
    n = len(ix); Gs = rows(mGy, ix, nu); Ft = Ftilde(ix); Y2 = Ft * Ft.T
    Y2i = mp.inverse(Y2)
    Ht = Y2i * Gs * mp.inverse(Gs.T * Y2i * Gs) * S        # Alstad 2009 eq.31, H^T (n x nu)
    H = Ht.T
    M = -S * mp.inverse(H * Gs) * H * Ft
    out = losses_from_M(M, n)
    Gt = Gs * Sinv; lam = mp.eigsy(Gt.T * Y2i * Gt, eigvals_only=True)
    out['worst_eig_form'] = float(mp.mpf(1)/2/min(lam))
    Hn = H / mp.mnorm(H, 'f')   # Frobenius-normalised
    out['H_alstad_eq31_fro_normalised'] = [[float(Hn[i, j]) for j in range(n)] for i in range(nu)]
    return out
mJt = hcat(S, S * mp.inverse(mJ) * mJd)      # J~ = [Juu^1/2, Juu^1/2 Juu^-1 Jud]
def null_space(ix):
    n = len(ix); Gs = rows(mGy, ix, nu); Gt = hcat(Gs, rows(mGyd, ix, nd)); Wn = mp.diag([me[i] for i in ix])
    if n < nu + nd:   # pinv(Gt) for full row rank
        H = mJt * Gt.T * mp.inverse(Gt * Gt.T)
    else:             # Jt * pinv(Wn^-1 Gt) * Wn^-1 (Alstad eq.41), full column rank
        A = mp.inverse(Wn) * Gt
        H = mJt * mp.inverse(A.T * A) * A.T * mp.inverse(Wn)
    M = -S * mp.inverse(H * Gs) * H * Ftilde(ix)
    return losses_from_M(M, n)
def cond(ix): return float(np.linalg.cond(Gy[list(ix)]))

names = ['P2','T2','T3','F2','F100','T201','F3','F5','F200','F1']
evap = dict(
  source=dict(repo='feslima/pySOC', commit=COMMIT, input_file='pysoc/tests/soc/mat_files/input/helm_hen_input.mat',
              identical_copy='pysoc/tests/soc/mat_files/input/matrices_self_opt_100pts.mat (same Gy,Gyd,Juu,Jud; Wd, Wny stored as diagonal matrices; plus d=[5,40,25])'),
  ny=ny, nu=nu, nd=nd,
  measurements=names,
  measurement_descriptions=['Separator operating pressure [kPa]','Product temperature [degC]','Vapour temperature [degC]','Product flowrate [kg/min]','Steam flowrate [kg/min]','Cooling water outlet temperature [degC]','Circulating flowrate [kg/min]','Condensate flowrate [kg/min]','Cooling water flowrate [kg/min]','Feed flowrate [kg/min]'],
  measurement_names_source='comment block at top of pysoc/tests/soc/m_files/H_eval.m ("same as Kariwala 2008")',
  inputs_inferred=['F200','F1'], inputs_note='NOT stated in pySOC; inferred because Gy rows 9 (F200) and 10 (F1) are the identity rows [1,0],[0,1].',
  disturbances_inferred=['X1','T1','T200'], disturbances_note='NOT stated in pySOC; inferred from d=[5,40,25] in matrices_self_opt_100pts.mat (feed composition %, feed temperature degC, cooling-water inlet temperature degC, as in Kariwala et al. 2008) and Wd=diag(0.25,8,5) = 5%/20%/20% of those nominal values.',
  d_nominal=[5.0, 40.0, 25.0],
  Gy=L(Gy), Gyd=L(Gyd), Juu=L(Juu), Jud=L(Jud),
  Wd_diag=L(md), Wn_diag=L(me), Wd=L(np.diag(md)), Wn=L(np.diag(me)),
  conventions=dict(
     F='F = Gyd - Gy Juu^-1 Jud (pySOC writes F = -(Gy/Juu*Jud - Gyd))',
     Ftilde='Ftilde = [F Wd, Wn] restricted to the subset rows; Wn = diag(Wn_diag[subset])',
     M='M = -Juu^1/2 (H Gy_s)^-1 H Ftilde_s',
     worst='1/2 * sigma_max(M)^2',
     avg_uniform_fixture='||M||_F^2 / (6 (n + nd)), n = subset size (this is what the fixtures call Avg_Loss)',
     half_fro2='||M||_F^2 / 2 = 3 (n + nd) * avg_uniform (plantwide criterion; DERIVED, not a fixture)'),
  expected={}, derived={})

def fixture_block(path, key, method, n):
    o = loadmat(R + path)
    idx = o['index_CV'].astype(int); W = o[key].ravel(); A = o['Avg_Loss'].ravel()
    rowsout = []
    for i in range(len(W)):
        ix = [int(k) - 1 for k in idx[i]]
        ref = exact_local(ix) if method == 'exact_local' else null_space(ix)
        rel_w = abs(W[i] - ref['worst']) / ref['worst']; rel_a = abs(A[i] - ref['avg_uniform']) / ref['avg_uniform']
        rowsout.append(dict(subset=[int(k) for k in idx[i]], worst=float(W[i]), avg_uniform=float(A[i]),
             half_fro2_derived=float(3*(n+nd)*A[i]), cond_Gy_subset=cond(ix),
             mp60_worst=ref['worst'], mp60_avg_uniform=ref['avg_uniform'],
             rel_err_fixture_vs_mp60=max(rel_w, rel_a), reproducible_1e8=bool(max(rel_w, rel_a) < 1e-8)))
    return dict(file=path, mat_variables={'worst': key, 'avg': 'Avg_Loss', 'subsets': 'index_CV (1-based, uint8)'},
                pysoc_test='pysoc/tests/soc/soc_pytest/test_socmatlab.py::' + ('test_helm_result' if 'helm' in path else 'test_hen_result'),
                method=method, subset_size=n, criterion_order='rows sorted ascending by worst-case loss (all C(10,n) subsets)',
                n_rows=len(W), n_reproducible_1e8=sum(r['reproducible_1e8'] for r in rowsout), rows=rowsout)

evap['expected']['helm_ss2'] = fixture_block('soc/mat_files/output/helm/ss2.mat', 'Loss_Exact', 'exact_local', 2)
evap['expected']['hen_ss2'] = fixture_block('soc/mat_files/output/hen/ss2.mat', 'Loss_null', 'null_space', 2)
evap['expected']['hen_ss3'] = fixture_block('soc/mat_files/output/hen/ss3.mat', 'Loss_null', 'null_space', 3)

# derived: exact local method for all subsets of size 2..10 (not pySOC fixtures)
der = {}
for n in range(2, 11):
    lst = []
    for ix in itertools.combinations(range(ny), n):
        r = exact_local(list(ix))
        lst.append(dict(subset=[k+1 for k in ix], worst=r['worst'], worst_eig_form=r['worst_eig_form'], avg_uniform=r['avg_uniform'],
                        half_fro2=r['half_fro2'], cond_Gy_subset=cond(ix), H=r['H_alstad_eq31_fro_normalised']))
    lst.sort(key=lambda d: d['worst'])
    for d in lst[5:]: d.pop('H')
    der[f'n{n}'] = lst
evap['derived']['exact_local_mp60'] = dict(note='DERIVED here with mpmath (60 digits) from the double-precision inputs; NOT a pySOC fixture. Sorted by worst-case loss. H (Alstad 2009 eq.31, nu x n, scaled to unit Frobenius norm) given for the 5 best subsets of each size only; H is unique only up to a left nu x nu invertible factor.',
                                            by_size=der)
json.dump(evap, open(OUT + 'evaporator.json', 'w'), indent=1)

# ---------------- Yi Cao random case ----------------
inp = loadmat(R + 'bnb/mat_files/pb3wc/input/ny40_nu15_nd5_input.mat')
G, Gd, Juu2, Jud2, Wd2, Wn2 = [inp[k] for k in ['G','Gd','Juu','Jud','Wd','Wn']]
Y = np.hstack([(G @ np.linalg.inv(Juu2) @ Jud2 - Gd) @ Wd2, Wn2]); Gt = G @ np.linalg.inv(np.real(sqrtm(Juu2))); Y2 = Y @ Y.T
def wc(sset):
    s = np.array(sset) - 1
    C = np.linalg.cholesky(Y2[np.ix_(s, s)]); X = np.linalg.solve(C, Gt[s]); lam = np.linalg.eigvalsh(X.T @ X)
    return 0.5 / lam.min(), 0.5 * np.sum(1/lam)   # worst, 1/2||M||_F^2
cao = dict(source=dict(repo='feslima/pySOC', commit=COMMIT, input_file='pysoc/tests/bnb/mat_files/pb3wc/input/ny40_nu15_nd5_input.mat',
           generator='pysoc/tests/bnb/m_files/randcase.m (Yi Cao, 2009): G=randn(ny,nu); Gd=rand(ny,nd); Wd=diag(rand(nd,1)); Wn=diag(rand(ny,1)); x=randn(nu,nu+2*ny+nd); Juu=diag(sum(x.*x,2)); Jud=rand(nu,nd). No seed in the repo; G(1,1)=0.53767... suggests MATLAB rng default (Mersenne Twister seed 0). The data themselves are in the .mat file and are reproduced here.'),
           ny=40, nu=15, nd=5, model='y = G u + Gd Wd d + Wn e',
           Gy=L(G), Gyd=L(Gd), Juu=L(Juu2), Jud=L(Jud2), Wd_diag=L(np.diag(Wd2)), Wn_diag=L(np.diag(Wn2)),
           notes='Juu, Wd, Wn are diagonal in the file (off-diagonals exactly 0). The .mat names are G, Gd, Juu, Jud, Wd, Wn (full matrices), nu, ny, nd.',
           results={})
for f in sorted(glob.glob(R + 'bnb/mat_files/pb3wc/results/*.mat')):
    r = loadmat(f); n = int(re.search(r'_n(\d+)_', f).group(1)); nc = int(re.search(r'_nc(\d+)', f).group(1))
    B = r['B'].ravel(); ss = r['sset'].astype(int)
    chk = [wc(s) for s in ss]
    rel = [abs(c[0] - b_) / b_ for c, b_ in zip(chk, B)]
    cao['results'][f'n{n}_nc{nc}'] = dict(file=f.replace(R, 'pysoc/tests/'), n=n, K=nc, algorithm='pb3wc (PB3; for n = nu it is equivalent to B3)',
        B_worst_case_loss=L(B), sset=ss.tolist(), ops=[int(x) for x in r['ops'].ravel()], ops_meaning='[terminal, nodes, sub-nodes, calls] (MATLAB 1..4)',
        flag=int(r['flag'].ravel()[0]), ctime_matlab_s=float(r['ctime'].ravel()[0]),
        half_fro2_derived=[c[1] for c in chk], max_rel_err_B_vs_independent_f64=float(max(rel)))
json.dump(cao, open(OUT + 'cao_ny40_nu15_nd5.json', 'w'), indent=1)
for k, v in cao['results'].items(): print(k, v['ops'], v['max_rel_err_B_vs_independent_f64'])
for k, v in evap['expected'].items(): print(k, v['n_rows'], v['n_reproducible_1e8'])

# ---------------- the files the tests read ----------------
DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'crates', 'soc', 'tests', 'data', '')
matrices = dict(inputs=['F200', 'F1'], disturbances=['X1', 'T1', 'T200'], measurements=names,
                Gy=L(Gy), Gyd=L(Gyd), Juu=L(Juu), Jud=L(Jud), Wd=L(md), Wn=L(me))
json.dump(matrices, open(DATA + 'evaporator.json', 'w'), indent=1)
keep = ('subset', 'worst', 'avg_uniform', 'reproducible_1e8', 'mp60_worst', 'mp60_avg_uniform')
rows_of = {k: [{f: r[f] for f in keep} for r in v['rows']] for k, v in evap['expected'].items()}
json.dump(dict(source=evap['source'], **rows_of), open(DATA + 'evaporator_pysoc.json', 'w'), indent=1)
strip = lambda r: dict(subset=r['subset'], worst=r['worst'], half_fro2=r['half_fro2'])
best = {k: dict(by_worst=[strip(r) for r in sorted(v, key=lambda r: r['worst'])[:10]],
                by_average=[strip(r) for r in sorted(v, key=lambda r: r['half_fro2'])[:10]]) for k, v in der.items()}
json.dump(dict(by_size=best), open(DATA + 'evaporator_mp60_best.json', 'w'), indent=1)
label = lambda p, n: [f'{p}{k + 1}' for k in range(n)]
json.dump(dict(inputs=label('u', 15), disturbances=label('d', 5), measurements=label('y', 40), Gy=L(G), Gyd=L(Gd),
               Juu=L(Juu2), Jud=L(Jud2), Wd=L(np.diag(Wd2)), Wn=L(np.diag(Wn2))),
          open(DATA + 'cao_ny40_nu15_nd5.json', 'w'), indent=1)
pb3 = [dict(n=v['n'], K=v['K'], worst_case_loss=v['B_worst_case_loss'], subsets=v['sset'])
       for k, v in sorted(cao['results'].items()) if v['K'] == 100]
json.dump(dict(source=cao['source'], results=pb3), open(DATA + 'cao_ny40_nu15_nd5_pb3.json', 'w'), indent=1)
