#!/usr/bin/env python3
"""Regenerate crates/thermo/data/library.json (the built-in component library of plantwide).

This is a provenance tool, not part of the build: it documents exactly where every number in
library.json comes from and how it was converted to SI.  Run it only when the data set changes,
then run tools/verify_library.py.

    pip install chemicals numpy scipy      # chemicals ships the Perry's/DIPPR tables as data files
    python3 tools/build_library.py

Sources (cited in library.json, never the Python package):
  * Perry's Chemical Engineers' Handbook, 8th ed. (Green & Perry, McGraw-Hill 2008), section 2:
      - Table 2-8   vapour pressure, DIPPR eq. 101, P in Pa                       (chemicals: Psat_data_Perrys2_8)
      - Table 2-32  liquid density, DIPPR eq. 105, kmol/m3 (chemicals stores mol/m3: C1 already x1000)
                                                                                  (chemicals: rho_data_Perry_8E_105_l)
      - Table 2-141 critical constants and acentric factors (MW, Tc, Pc, omega)  (transcribed below)
      - Table 2-150 heat of vaporization, DIPPR eq. 106, J/kmol (chemicals stores J/mol)
                                                                                  (chemicals: phase_change_data_Perrys2_150)
      - Table 2-153 liquid heat capacity, DIPPR eq. 100 (J/kmol/K) or eq. 114     (chemicals: Cp_data_Perry_Table_153_100/114)
      - Table 2-156 ideal-gas heat capacity, DIPPR eq. 107, J/kmol/K             (transcribed below)
  * Perry's 7th ed. Table 2-30: water liquid density, DIPPR eq. 105 (the 8th-ed. table gives water as a
    polynomial that the Dippr105 form cannot hold).
  * Normal boiling points: CRC Handbook of Chemistry and Physics, 95th ed. (2014), "Enthalpy of vaporization"
    table (Tb column); biphenyl and isobutene from the CRC "Physical constants of organic compounds" table;
    CO2 (which has no normal boiling point) its normal sublimation temperature, and H2S, from Yaws (2014).
  * Isopropanol vapour pressure: Poling, Prausnitz & O'Connell, 5th ed., Appendix A Antoine constants
    (Perry's Table 2-8 misses its normal boiling point by 0.7 K).  See PSAT_OVERRIDE / TB_OVERRIDE.
  * Binary pairs: see the `pairs` list (Aspen Plus databank NRTL for ethanol-water and methanol-water,
    DECHEMA-derived NRTL for acetone-water via Smith-Van Ness-Abbott, ChemSep Wilson for the alcohol-water pairs).

Tables 2-141 and 2-156 are not in `chemicals`; the rows below were transcribed from the open
transcription of Perry's 8th ed. tables in github.com/DANA-Laboratory/ThermodynamicsTable.jl
(src/Tables/perryCriticals_Table2_141.table, perryHeatCapIdealGas_Table2_156.table) and checked
for self-consistency (Table 2-156 prints Cp at Tmin and Tmax; both are reproduced to <0.2 %).
Table 2-156 columns are printed as C1x1e-5, C2x1e-5, C3x1e-3, C4x1e-5, C5.
"""

import json
import math
import os
import re
import sys
import warnings

import numpy as np

warnings.filterwarnings("ignore")

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "crates", "thermo", "data", "library.json")

# name, formula, CAS, Perry's 8th-ed. compound number (same number in every section-2 table)
COMPS = [
    # water and oxygenates
    ("water", "H2O", "7732-18-5", 342),
    ("methanol", "CH4O", "67-56-1", 194),
    ("ethanol", "C2H6O", "64-17-5", 126),
    ("1-propanol", "C3H8O", "71-23-8", 296),
    ("isopropanol", "C3H8O", "67-63-0", 297),
    ("1-butanol", "C4H10O", "71-36-3", 34),
    ("ethylene glycol", "C2H6O2", "107-21-1", 137),
    ("acetone", "C3H6O", "67-64-1", 5),
    ("methyl ethyl ketone", "C4H8O", "78-93-3", 222),
    ("acetic acid", "C2H4O2", "64-19-7", 3),
    ("ethyl acetate", "C4H8O2", "141-78-6", 127),
    ("mtbe", "C5H12O", "1634-04-4", 244),
    ("phenol", "C6H6O", "108-95-2", 291),
    ("chloroform", "CHCl3", "67-66-3", 55),
    # aromatics
    ("benzene", "C6H6", "71-43-2", 16),
    ("toluene", "C7H8", "108-88-3", 325),
    ("ethylbenzene", "C8H10", "100-41-4", 129),
    ("styrene", "C8H8", "100-42-5", 312),
    ("o-xylene", "C8H10", "95-47-6", 344),
    ("m-xylene", "C8H10", "108-38-3", 343),
    ("p-xylene", "C8H10", "106-42-3", 345),
    ("cumene", "C9H12", "98-82-8", 62),
    ("diphenyl", "C12H10", "92-52-4", 24),
    # saturated C5+ hydrocarbons
    ("cyclohexane", "C6H12", "110-82-7", 65),
    ("n-pentane", "C5H12", "109-66-0", 279),
    ("n-hexane", "C6H14", "110-54-3", 171),
    ("n-heptane", "C7H16", "142-82-5", 160),
    ("n-octane", "C8H18", "111-65-9", 265),
    ("n-decane", "C10H22", "124-18-5", 74),
    # light hydrocarbons
    ("methane", "CH4", "74-82-8", 193),
    ("ethane", "C2H6", "74-84-0", 125),
    ("ethylene", "C2H4", "74-85-1", 135),
    ("propane", "C3H8", "74-98-6", 295),
    ("propylene", "C3H6", "115-07-1", 305),
    ("n-butane", "C4H10", "106-97-8", 31),
    ("isobutane", "C4H10", "75-28-5", 236),
    ("1-butene", "C4H8", "106-98-9", 36),
    ("isobutene", "C4H8", "115-11-7", 238),
    ("1,3-butadiene", "C4H6", "106-99-0", 30),
    # permanent gases and inorganics
    ("hydrogen", "H2", "1333-74-0", 183),
    ("nitrogen", "N2", "7727-37-9", 249),
    ("oxygen", "O2", "7782-44-7", 275),
    ("carbon monoxide", "CO", "630-08-0", 49),
    # Carbon dioxide is deliberately NOT in the library: it has no normal boiling point (it sublimes at
    # 194.67 K; 101325 Pa is below its triple point, 216.58 K / 518 kPa), so no tabulated tb is consistent
    # with a liquid vapour-pressure curve (Perry's Table 2-8 extrapolated gives 185.6 K).  Define it inline
    # where needed, or add ("carbon dioxide", "CO2", "124-38-9", 47) here (tb then comes from Yaws, 194.67 K).
    ("hydrogen sulfide", "H2S", "7783-06-4", 188),
    ("ammonia", "H3N", "7664-41-7", 12),
]

# Perry's 8th ed. Table 2-141: no; MW; Tc [K]; Pc [MPa]; Vc [m3/kmol]; Zc; omega
PERRY_2_141 = """
3;60.052;591.95;5.786;0.177;0.208;0.4665
5;58.079;508.2;4.701;0.209;0.233;0.3065
12;17.031;405.65;11.28;0.07247;0.242;0.2526
16;78.112;562.05;4.895;0.256;0.268;0.2103
24;154.208;773;3.38;0.497;0.261;0.4029
30;54.090;425;4.32;0.221;0.27;0.1950
31;58.122;425.12;3.796;0.255;0.274;0.2002
34;74.122;563.1;4.414;0.273;0.258;0.5883
36;56.106;419.5;4.02;0.241;0.278;0.1845
47;44.010;304.21;7.383;0.094;0.274;0.2236
49;28.010;132.92;3.499;0.0944;0.299;0.0482
55;119.378;536.4;5.472;0.239;0.293;0.2219
62;120.192;631;3.209;0.434;0.265;0.3274
65;84.159;553.8;4.08;0.308;0.273;0.2081
74;142.282;617.7;2.11;0.617;0.254;0.4923
125;30.069;305.32;4.872;0.1455;0.279;0.0995
126;46.068;514;6.137;0.168;0.241;0.6436
127;88.105;523.3;3.88;0.286;0.255;0.3664
129;106.165;617.15;3.609;0.374;0.263;0.3035
135;28.053;282.34;5.041;0.131;0.281;0.0862
137;62.068;720;8.2;0.191;0.262;0.5068
160;100.202;540.2;2.74;0.428;0.261;0.3495
171;86.175;507.6;3.025;0.371;0.266;0.3013
183;2.016;33.19;1.313;0.064147;0.305;-0.2160
188;34.081;373.53;8.963;0.0985;0.284;0.0942
193;16.042;190.564;4.599;0.0986;0.286;0.0115
194;32.042;512.5;8.084;0.117;0.222;0.5658
222;72.106;535.5;4.15;0.267;0.249;0.3234
236;58.122;407.8;3.64;0.259;0.278;0.1835
238;56.106;417.9;4;0.239;0.275;0.1948
244;88.148;497.1;3.287;0.314;0.25;0.2466
249;28.013;126.2;3.4;0.08921;0.289;0.0377
265;114.229;568.7;2.49;0.486;0.256;0.3996
275;31.999;154.58;5.043;0.0734;0.288;0.0222
279;72.149;469.7;3.37;0.313;0.27;0.2515
291;94.111;694.25;6.13;0.229;0.243;0.4435
295;44.096;369.83;4.248;0.2;0.276;0.1523
296;60.095;536.8;5.169;0.219;0.254;0.6209
297;60.095;508.3;4.765;0.222;0.25;0.6544
305;42.080;364.85;4.6;0.185;0.281;0.1376
312;104.149;636;3.84;0.352;0.256;0.2971
325;92.138;591.75;4.108;0.316;0.264;0.2640
342;18.015;647.096;22.064;0.0559472;0.229;0.3449
343;106.165;617;3.541;0.375;0.259;0.3265
344;106.165;630.3;3.732;0.37;0.264;0.3101
345;106.165;616.2;3.511;0.378;0.259;0.3218
"""

# Perry's 8th ed. Table 2-156: no; MW; C1e-5; C2e-5; C3e-3; C4e-5; C5; Tmin; Cp(Tmin)e-5; Tmax; Cp(Tmax)e-5
PERRY_2_156 = """
3;60.052;0.402;1.3675;1.262;0.7003;569.7;50;0.4020;1500;1.5756
5;58.079;0.5704;1.632;1.607;0.968;731.5;200;0.6049;1500;1.8820
12;17.031;0.33427;0.4898;2.036;0.2256;882;100;0.3343;1500;0.6647
16;78.112;0.44767;2.3085;1.4792;1.6836;677.66;200;0.5358;1500;2.4157
24;154.208;1.0759;4.2105;1.9041;4.1785;828.81;200;1.1481;1500;4.5557
30;54.090;0.5095;1.705;1.5324;1.337;685.6;200;0.5756;1500;1.9555
31;58.122;0.7134;2.43;1.63;1.5033;730.42;200;0.7673;1500;2.6602
34;74.122;0.7454;2.5907;1.6073;1.732;712.4;200;0.8162;1500;2.8509
36;56.106;0.64257;2.0618;1.6768;1.3324;757.06;250;0.7571;1500;2.2898
47;44.010;0.2937;0.3454;1.428;0.264;588;50;0.2937;5000;0.6335
49;28.010;0.29108;0.08773;3.0851;0.084553;1538.2;60;0.2911;1500;0.3521
55;119.378;0.3942;0.6573;0.928;0.493;399.6;100;0.4048;1500;1.0063
62;120.192;1.081;3.7932;1.7505;3.0027;794.8;200;1.1480;1500;4.1808
65;84.159;0.432;3.735;1.192;1.635;530.1;100;0.4366;1500;3.6516
74;142.282;1.672;5.353;1.6141;3.782;742;200;1.7967;1500;6.0932
125;30.069;0.40326;1.3422;1.6555;0.73223;752.87;200;0.4256;1500;1.4562
126;46.068;0.492;1.4577;1.6628;0.939;744.7;200;0.5224;1500;1.6576
127;88.105;0.9981;2.0931;2.0226;1.803;928.05;200;1.0126;1500;2.6594
129;106.165;0.7844;3.399;1.559;2.426;702;200;0.8912;1500;3.6147
135;28.053;0.3338;0.9479;1.596;0.551;740.8;60;0.3338;1500;1.0987
137;62.068;0.63012;1.4584;1.673;0.97296;773.65;300;0.7800;1500;1.8095
160;100.202;1.2015;4.001;1.6766;2.74;756.4;200;1.2828;1500;4.4283
171;86.175;1.044;3.523;1.6946;2.369;761.6;200;1.1117;1500;3.8620
183;2.016;0.27617;0.0956;2.466;0.0376;567.6;250;0.2843;1500;0.3225
188;34.081;0.33288;0.26086;0.9134;-0.17979;949.4;100;0.3329;1500;0.5143
193;16.042;0.33298;0.79933;2.0869;0.41602;991.96;50;0.3330;1500;0.8890
194;32.042;0.39252;0.879;1.9165;0.53654;896.7;200;0.3980;1500;1.0533
222;72.106;0.784;2.1032;1.5488;1.1855;693;200;0.8397;1500;2.4816
236;58.122;0.6549;2.4776;1.587;1.575;706.99;200;0.7218;1500;2.6656
238;56.106;0.6125;2.066;1.545;1.2057;676;200;0.6763;1500;2.2814
244;88.148;0.9779;3.091;1.643;2.099;731.191;298;1.3522;1500;3.4779
249;28.013;0.29105;0.086149;1.7016;0.0010347;909.79;50;0.2911;1500;0.3484
265;114.229;1.3554;4.431;1.6356;3.054;746.4;200;1.4529;1500;4.9764
275;31.999;0.29103;0.1004;2.5265;0.09356;1153.8;50;0.2910;1500;0.3653
279;72.149;0.8805;3.011;1.6502;1.892;747.6;200;0.9404;1500;3.2927
291;94.111;0.434;2.445;1.152;1.512;507;100;0.4401;1500;2.6045
295;44.096;0.5192;1.9245;1.6265;1.168;723.6;200;0.5632;1500;2.0556
296;60.095;0.619;2.0213;1.6293;1.2956;727.4;200;0.6665;1500;2.2458
297;60.095;0.73145;2.0313;1.9375;1.4815;843.37;298.15;0.8966;1500;2.2760
305;42.080;0.43852;1.506;1.3988;0.74754;616.46;130;0.4436;1500;1.6817
312;104.149;0.893;2.1503;0.772;0.999;2442;100;0.8931;1500;3.2416
325;92.138;0.5814;2.863;1.4406;1.898;650.43;200;0.7016;1500;3.0029
342;18.015;0.33363;0.2679;2.6105;0.08896;1169;100;0.3336;2273.15;0.5276
343;106.165;0.7568;3.3924;1.496;2.247;675.9;200;0.8759;1500;3.5920
344;106.165;0.8521;3.2954;1.4944;2.115;675.8;200;0.9643;1500;3.5965
345;106.165;0.7512;3.397;1.4928;2.247;675.1;200;0.8710;1500;3.5923
"""

# Overrides where the Perry's Table 2-8 DIPPR 101 equation misses the CRC normal boiling point by > 0.5 K
# (checked by tools/verify_library.py):
#   isopropanol: Table 2-8 gives psat = 1 atm at 354.76 K vs CRC 355.45 K (Poling/Yaws 355.41 K) -> use the Antoine
#   constants of Poling, Prausnitz & O'Connell, The Properties of Gases and Liquids 5th ed., Appendix A
#   (log10 P[bar] = 5.24268 - 1580.92/(T[C] + 219.61), 281-373 K), rewritten for P in Pa, T in K.
PSAT_OVERRIDE = {
    "67-63-0": ({"form": "antoine", "a": 10.24268, "b": 1580.92, "c": -53.54, "tmin": 281.28, "tmax": 373.46},
                "psat: Poling, Prausnitz & O'Connell 5th ed. Appendix A Antoine constants (281-373 K; Perry's Table 2-8 "
                "misses the normal boiling point by 0.7 K)"),
}
#   hydrogen sulfide: CRC lists 213.60 K, while DIPPR (Table 2-8: 212.93 K), Poling's Antoine (212.84 K) and Yaws (212.8 K)
#   agree on ~212.8 K -> tb from Yaws.
TB_OVERRIDE = {"7783-06-4": (212.8, "tb: Yaws (2014) (CRC 95th lists 213.60 K, inconsistent with DIPPR and Poling)")}

# Water liquid density: Perry's 7th ed. Table 2-30, DIPPR 105, kmol/m3, 273.16-333.15 K.
WATER_105_7TH = (5.459, 0.30542, 647.13, 0.081)

R_CAL = 1.98721  # cal/(mol K)


def parse(block):
    rows = {}
    for line in block.strip().splitlines():
        f = line.split(";")
        rows[int(f[0])] = [float(v) for v in f[1:]]
    return rows


def r(x, sig=8):
    """Round to `sig` significant digits (keeps the JSON readable; far below data precision)."""
    if x == 0 or not math.isfinite(x):
        return x
    return float(f"{x:.{sig}g}")


def eq114(T, Tc, A, B, C, D):
    t = 1.0 - T / Tc
    return A * A / t + B - 2 * A * C * t - A * D * t**2 - C * C * t**3 / 3 - C * D * t**4 / 2 - D * D * t**5 / 5


def main():
    from chemicals import heat_capacity as hc, phase_change as pc, vapor_pressure as vp, volume as vol, miscdata
    from chemicals.data_reader import data_source  # noqa: F401  (forces lazy loading)
    import chemicals
    import pandas as pd

    t141 = parse(PERRY_2_141)
    t156 = parse(PERRY_2_156)
    p28 = vp.Psat_data_Perrys2_8
    p150 = pc.phase_change_data_Perrys2_150
    p153 = hc.Cp_data_Perry_Table_153_100
    p153b = hc.Cp_data_Perry_Table_153_114
    p105 = vol.rho_data_Perry_8E_105_l
    d = os.path.dirname(chemicals.__file__)
    crc_hvap = pd.read_csv(os.path.join(d, "Phase Change", "CRC Handbook Heat of Vaporization.tsv"), sep="\t", index_col=0)
    crc_org = miscdata.CRC_organic_data
    yaws_tb = pd.read_csv(os.path.join(d, "Phase Change", "Yaws Boiling Points.tsv"), sep="\t", index_col=0)

    comps = []
    for name, formula, cas, no in COMPS:
        mw, tc, pc_mpa, _vc, _zc, omega = t141[no]
        notes = []
        # ---- normal boiling point
        if cas in TB_OVERRIDE:
            tb, tb_src = TB_OVERRIDE[cas]
        elif cas in crc_hvap.index and not math.isnan(crc_hvap.loc[cas, "Tb"]):
            tb = float(crc_hvap.loc[cas, "Tb"])
            tb_src = "tb: CRC Handbook 95th ed., enthalpy-of-vaporization table"
        elif cas in crc_org.index and not math.isnan(crc_org.loc[cas, "Tb"]):
            tb = float(crc_org.loc[cas, "Tb"])
            tb_src = "tb: CRC Handbook 95th ed., physical constants of organic compounds"
        else:
            tb = float(yaws_tb.loc[cas, "Tb"])
            tb_src = "tb: normal sublimation temperature (no normal boiling point; triple point 216.6 K, 518 kPa), Yaws (2014)"
        # ---- vapour pressure, Perry's Table 2-8 (DIPPR 101, Pa)
        row = p28.loc[cas]
        psat = {"form": "dippr101", "c": [r(row.C1), r(row.C2), r(row.C3), r(row.C4), r(row.C5)],
                "tmin": float(row.Tmin), "tmax": float(row.Tmax)}
        psat_src = "psat Table 2-8 (DIPPR 101)"
        if cas in PSAT_OVERRIDE:
            psat, psat_src = PSAT_OVERRIDE[cas]
        # ---- ideal-gas Cp, Perry's Table 2-156 (DIPPR 107, J/kmol/K -> J/mol/K)
        c = t156[no]
        assert abs(c[0] - mw) < 1e-6, (name, c[0], mw)
        cp_ig = {"form": "dippr107",
                 "c": [r(c[1] * 1e5 / 1e3), r(c[2] * 1e5 / 1e3), r(c[3] * 1e3), r(c[4] * 1e5 / 1e3), r(c[5])]}
        # ---- liquid Cp, Perry's Table 2-153 (DIPPR 100, J/kmol/K -> J/mol/K)
        if cas in p153.index:
            row = p153.loc[cas]
            cp_liq = {"form": "dippr100", "c": [r(row.A / 1e3), r(row.B / 1e3), r(row.C / 1e3), r(row.D / 1e3), r(row.E / 1e3)]}
            cpl_src = "cp_liq: Perry's 8th Table 2-153 (eq. 100)"
        else:
            # Table 2-153 gives this compound only in DIPPR eq. 114 form (diverges at Tc); the library form is
            # eq. 100, so fit a quartic by least squares over Tmin..min(Tmax, 0.9 Tc).
            row = p153b.loc[cas]
            lo, hi = float(row.Tmin), min(float(row.Tmax), 0.9 * tc)
            T = np.linspace(lo, hi, 200)
            y = np.array([eq114(t, tc, row.A, row.B, row.C, row.D) for t in T]) / 1e3
            Ts = T / 100.0  # scaled for conditioning
            coef = np.polyfit(Ts, y, 4)[::-1]
            cc = [coef[k] / 100.0**k for k in range(5)]
            fit = sum(cc[k] * T**k for k in range(5))
            err = float(np.max(np.abs(fit - y) / y)) * 100
            cp_liq = {"form": "dippr100", "c": [r(v) for v in cc]}
            cpl_src = (f"cp_liq: quartic (eq. 100) least-squares fit to Perry's 8th Table 2-153 eq. 114 over "
                       f"{lo:.1f}-{hi:.1f} K (max dev {err:.2f} %)")
            notes.append(f"{name}: eq114 fit max dev {err:.3f}% over {lo}-{hi}")
        # ---- heat of vaporization, Perry's Table 2-150 (DIPPR 106; chemicals stores J/mol)
        row = p150.loc[cas]
        hvap = {"form": "dippr106", "c": [r(row.C1), r(row.C2), r(row.C3), r(row.C4), 0.0], "tc": float(row.Tc)}
        # ---- liquid density, Perry's Table 2-32 (DIPPR 105; chemicals stores mol/m3)
        if cas == "7732-18-5":
            a, b, cc3, dd = WATER_105_7TH
            vliq = {"form": "dippr105", "c": [r(a * 1e3), b, cc3, dd]}
            rho_src = "vliq: Perry's 7th ed. Table 2-30 (DIPPR 105, 273-333 K; the 8th-ed. Table 2-32 water entry is not eq. 105)"
        else:
            row = p105.loc[cas]
            vliq = {"form": "dippr105", "c": [r(row.C1), r(row.C2), r(row.C3), r(row.C4)]}
            rho_src = "vliq: Perry's 8th Table 2-32 (DIPPR 105)"
        source = ("Perry's Chemical Engineers' Handbook 8th ed.: mw, tc, pc, omega Table 2-141; " + psat_src + "; "
                  "cp_ig Table 2-156 (DIPPR 107); hvap Table 2-150 (DIPPR 106); " + cpl_src + "; " + rho_src + "; " + tb_src)
        comps.append({
            "name": name, "formula": formula, "cas": cas,
            "mw": r(mw / 1e3), "tb": tb, "tc": tc, "pc": r(pc_mpa * 1e6), "omega": omega,
            "psat": psat, "cp_ig": cp_ig, "cp_liq": cp_liq, "hvap": hvap, "vliq": vliq,
            "source": source,
        })
        for n in notes:
            print(n, file=sys.stderr)

    # ------------------------------------------------------------------ binary pairs
    def vliq298(name):
        cc = next(x for x in comps if x["name"] == name)["vliq"]["c"]
        rho = cc[0] / cc[1] ** (1 + (1 - 298.15 / cc[2]) ** cc[3])
        return 1.0 / rho

    def nrtl_cal(i, j, Aij, Aji, alpha, source):
        """DECHEMA form: tau_ij = A_ij/(R T), A in cal/mol  ->  b_ij = A_ij/R [K], a_ij = 0."""
        return {"model": "nrtl", "i": i, "j": j, "a_ij": 0.0, "a_ji": 0.0,
                "b_ij": r(Aij / R_CAL, 7), "b_ji": r(Aji / R_CAL, 7), "alpha": alpha, "source": source}

    def wilson_cal(i, j, Aij, Aji, source):
        """DECHEMA form: Lambda_ij = (V_j/V_i) exp(-A_ij/(R T)), A_ij = lambda_ij - lambda_ii in cal/mol
        -> a_ij = ln(V_j/V_i), b_ij = -A_ij/R.  Molar volumes: this library's vliq at 298.15 K."""
        vi, vj = vliq298(i), vliq298(j)
        return {"model": "wilson", "i": i, "j": j,
                "a_ij": r(math.log(vj / vi), 7), "a_ji": r(math.log(vi / vj), 7),
                "b_ij": r(-Aij / R_CAL, 7), "b_ji": r(-Aji / R_CAL, 7), "alpha": 0.0, "source": source}

    pairs = [
        {"model": "nrtl", "i": "ethanol", "j": "water",
         "a_ij": -0.8009, "a_ji": 3.4578, "b_ij": 246.18, "b_ji": -586.0809, "alpha": 0.3,
         "source": ("Aspen Plus built-in binary databank, NRTL (APV 'VLE-IG' set, regressed by AspenTech from DECHEMA CDS "
                    "data), Aspen form tau_ij = a_ij + b_ij/T, c_ij = 0.3; numbers as widely reproduced, not re-read from an "
                    "Aspen installation. Reproduces the 101.325 kPa azeotrope (351.3 K, x_EtOH 0.895) with Perry's Table 2-8 psat. "
                    "(The DECHEMA set in the ChemSep nrtl.ipd file, A12 = -57.9601, A21 = 1241.7396 cal/mol, alpha 0.2937, "
                    "gives x_az 0.880 and was rejected.)")},
        {"model": "nrtl", "i": "methanol", "j": "water",
         "a_ij": -0.693, "a_ji": 2.7322, "b_ij": 172.987, "b_ji": -617.269, "alpha": 0.3,
         "source": ("Aspen Plus built-in binary databank, NRTL (APV 'VLE-IG' set), Aspen form tau_ij = a_ij + b_ij/T, "
                    "c_ij = 0.3; numbers as widely reproduced, not re-read from an Aspen installation. Against Kurihara et al., "
                    "J. Chem. Eng. Data 40 (1995) 679 (333.15 K) bubble temperatures within 0.31 K. (Alternative: DECHEMA CDS "
                    "Vol. I Part 1a p. 61, A12 = -189.0469, A21 = 792.8020 cal/mol, alpha 0.2999, via ChemSep nrtl.ipd: "
                    "within 0.98 K of the same data.)")},
        nrtl_cal("acetone", "water", 631.05, 1197.41, 0.5343,
                 "Smith, Van Ness & Abbott, Introduction to Chemical Engineering Thermodynamics 7th ed., Table 12.5 "
                 "(acetone(1)/water(2): NRTL b12 = 631.05, b21 = 1197.41 cal/mol, alpha = 0.5343; values from Gmehling & "
                 "Onken, DECHEMA CDS Vol. I); converted b_ij = b_ij(cal/mol)/R, a_ij = 0. Not checked against experimental "
                 "Txy data (none available to the verifier)."),
        wilson_cal("ethanol", "water", 382.30, 955.45,
                   "ChemSep interaction-parameter database (wilson.ipd, 'Ethanol/Water': A12 = 382.30, A21 = 955.45 cal/mol, "
                   "Wilson lambda_ij - lambda_ii); converted a_ij = ln(V_j/V_i) with this library's vliq at 298.15 K, "
                   "b_ij = -A_ij/R."),
        wilson_cal("methanol", "water", 205.30, 482.16,
                   "ChemSep interaction-parameter database (wilson.ipd, 'Methanol/Water': A12 = 205.30, A21 = 482.16 cal/mol, "
                   "Wilson lambda_ij - lambda_ii); converted a_ij = ln(V_j/V_i) with this library's vliq at 298.15 K, "
                   "b_ij = -A_ij/R."),
    ]

    lib = {
        "sources": [
            "Green, D. W.; Perry, R. H. (eds.), Perry's Chemical Engineers' Handbook, 8th ed., McGraw-Hill, 2008, Section 2 "
            "(DIPPR correlations): Table 2-8 vapour pressure (eq. 101), Table 2-32 liquid density (eq. 105), Table 2-141 "
            "critical constants and acentric factors, Table 2-150 heat of vaporization (eq. 106), Table 2-153 liquid heat "
            "capacity (eq. 100; eq. 114 entries refitted to eq. 100), Table 2-156 ideal-gas heat capacity (eq. 107).",
            "Perry, R. H.; Green, D. W., Perry's Chemical Engineers' Handbook, 7th ed., McGraw-Hill, 1997, Table 2-30 "
            "(water liquid density, DIPPR eq. 105).",
            "Haynes, W. M. (ed.), CRC Handbook of Chemistry and Physics, 95th ed., CRC Press, 2014: normal boiling points "
            "(enthalpy-of-vaporization table; physical constants of organic compounds).",
            "Yaws, C. L., Thermophysical Properties of Chemicals and Hydrocarbons, 2nd ed., Elsevier, 2014: CO2 normal "
            "sublimation temperature; H2S normal boiling point.",
            "Gmehling, J.; Onken, U., Vapor-Liquid Equilibrium Data Collection, DECHEMA Chemistry Data Series Vol. I "
            "(Frankfurt, 1977-): NRTL/Wilson parameters, via the ChemSep interaction-parameter files (Kooijman & Taylor) "
            "and via Smith, Van Ness & Abbott (below).",
            "Smith, J. M.; Van Ness, H. C.; Abbott, M. M., Introduction to Chemical Engineering Thermodynamics, 7th ed., "
            "McGraw-Hill, 2005, Table 12.5 (Wilson and NRTL parameters).",
            "Poling, B. E.; Prausnitz, J. M.; O'Connell, J. P., The Properties of Gases and Liquids, 5th ed., McGraw-Hill, "
            "2001, Appendix A (Antoine constants, isopropanol).",
            "Aspen Plus (AspenTech) built-in binary parameter databank, NRTL ethanol-water and methanol-water.",
            "Verification data (tools/verify_library.py): Kurihara, K.; Minoura, T.; Takeda, K.; Kojima, K., J. Chem. Eng. "
            "Data 40 (1995) 679-684 (methanol-water VLE); VDI Heat Atlas, 2nd ed., Springer, 2010 (PPDS liquid density "
            "and heat of vaporization).",
            "Units: SI throughout (kg/mol, K, Pa, J/mol, J/(mol K), mol/m3); Perry's J/kmol and kmol/m3 values converted.",
        ],
        "components": comps,
        "binary_pairs": pairs,
    }
    text = json.dumps(lib, indent=2, ensure_ascii=False)
    # keep short numeric arrays (correlation coefficients) on one line
    text = re.sub(r"\[\s*((?:-?[0-9.eE+-]+,\s*)*-?[0-9.eE+-]+)\s*\]",
                  lambda m: "[" + ", ".join(v.strip() for v in m.group(1).split(",")) + "]", text)
    with open(OUT, "w") as f:
        f.write(text + "\n")
    print(f"wrote {os.path.normpath(OUT)}: {len(comps)} components, {len(pairs)} binary pairs")


if __name__ == "__main__":
    main()
