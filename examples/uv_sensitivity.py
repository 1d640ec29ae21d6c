"""How the UV end of the loop integrals moves the 2-loop and propagator terms (issue: RPT's UV
sensitivity). For QMAX = 1e3, 10, 3, 1 h/Mpc (q_min = 1e-5) and the gm2012 spectrum at z = 0, prints
P15/P, P17/P, the propagator factors N2², N3² (δδ) and the 2-loop SPT correction over P_lin, as a
Markdown table. Run after `pip install ./python`:

    python examples/uv_sensitivity.py
"""

import pt_spectra as pt

K = [0.05, 0.1, 0.15, 0.2]
print("| QMAX [h/Mpc] | k [h/Mpc] | P15/P | P17/P | N2² | N3² | 2-loop correction/P | 2L-RPT-N2 / its QMAX = 1e3 value |")
print("|---|---|---|---|---|---|---|---|")
reference = None
for qmax in (1e3, 10.0, 3.0, 1.0):
    n3 = pt.real(model="2l-rpt-n3", k=K, terms=True, q_range=(1e-5, qmax))
    n2 = pt.real(model="2l-rpt-n2", k=K, terms=True, q_range=(1e-5, qmax))
    if reference is None:
        reference = n2["P_dd"]
    for i, k in enumerate(K):
        p = n3["P_lin"][i]
        print(f"| {qmax:g} | {k:.2f} | {n3['P15_dd'][i] / p:+.4f} | {n3['P17_dd'][i] / p:+.4f} | "
              f"{n2['N_dd'][i]:.4f} | {n3['N_dd'][i]:.4f} | {n3['P2loop_dd'][i] / p:+.4f} | "
              f"{n2['P_dd'][i] / reference[i]:.4f} |")
