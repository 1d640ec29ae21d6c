//! Prints the size of every generated kernel program (statements and operation counts), and what the
//! propagators cost in lane pairs under each symmetry of their arguments.
use kernelgen_core::pairing::{pair, Involution};
use kernelgen_core::{Program, Spec};

fn main() {
    let mut specs: Vec<Spec> = (2..=7)
        .map(|n| Spec::free(&format!("general_{n}"), n).unwrap())
        .collect();
    specs.extend(
        (1..=3).map(|x| Spec::propagator(&format!("propagator_{}", 2 * x + 1), x).unwrap()),
    );
    specs.extend((1..=5).map(|n| Spec::redshift(&format!("redshift_{n}"), n).unwrap()));
    let b = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    specs.push(
        Spec::new(
            "mode_coupling_2",
            b(&["k", "q"]),
            vec![vec![0, 1], vec![1, -1]],
        )
        .unwrap(),
    );
    specs.push(
        Spec::new(
            "mode_coupling_3",
            b(&["k", "q1", "q2"]),
            vec![vec![0, 1, 0], vec![0, 0, 1], vec![1, -1, -1]],
        )
        .unwrap(),
    );
    specs.push(
        Spec::new(
            "mode_coupling_4",
            b(&["k", "q1", "q2"]),
            vec![vec![0, 1, 0], vec![1, -1, 0], vec![0, 0, 1], vec![0, 0, -1]],
        )
        .unwrap(),
    );
    println!(
        "{:<18} {:>6} {:>6} {:>6} {:>6} {:>6} {:>8} {:>6}",
        "kernel", "stmts", "muls", "adds", "recips", "flops", "subkern", "splits"
    );
    for s in &specs {
        let p = Program::build(s);
        let c = p.op_counts();
        println!(
            "{:<18} {:>6} {:>6} {:>6} {:>6} {:>6} {:>8} {:>6}",
            s.name,
            c.statements,
            c.muls,
            c.adds,
            c.recips,
            c.flops(),
            p.stats.subkernels,
            p.stats.splits
        );
    }
    for x in 2..=3 {
        let program = Program::build(&Spec::propagator("p", x).unwrap());
        println!(
            "\npropagator_{} in lane pairs ({} direct statements):",
            2 * x + 1,
            program.op_counts().statements
        );
        for inv in Involution::candidates(&program.spec) {
            if let Some(p) = pair(&program, &inv) {
                let c = p.counts;
                println!(
                    "  {:32} {:>5} statements {:>4} swaps {:>5} mirrored {:>4} merged",
                    inv.describe(&program.spec),
                    c.statements,
                    c.swaps,
                    c.mirrored,
                    c.merged
                );
            }
        }
    }
}
