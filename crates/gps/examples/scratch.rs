use tubemem_gps::*;
use tubemem_material::laws::*;
fn main() {
    let law = AnssariBenamBucchi::new(1.0, 30.0).unwrap();
    let t = std::time::Instant::now();
    let l = limits::limit_points(&law, Hypothesis::Gps).unwrap();
    println!("{:?} in {:?}", l, t.elapsed());
    println!(
        "PS {:?}",
        limits::limit_points(&law, Hypothesis::Ps).unwrap()
    );
    println!(
        "NH {:?}",
        limits::limit_points(&neo_hookean(1.0).unwrap(), Hypothesis::Gps).unwrap()
    );
    println!(
        "MR0.1 {:?}",
        limits::limit_points(&MooneyRivlin::new(1.0, 0.1).unwrap(), Hypothesis::Gps).unwrap()
    );
    for ls in [1.3, 6.0] {
        for h in [Hypothesis::Gps, Hypothesis::Ps] {
            println!("{h:?} inflate {ls}: {:?}", inflate(&law, h, ls).unwrap());
            let c = flattening_curve(&law, h, ls, ls / 2.0, 11).unwrap();
            for s in c.iter().step_by(2) {
                println!(
                    "   rho {:.3} ls {:.5} lz {:.5} w {:.5} chi {:.5} F {:.5}",
                    s.rho, s.lambda_s, s.lambda_z, s.w, s.chi, s.force
                );
            }
        }
    }
    let t = std::time::Instant::now();
    let c = inflation_curve(&law, Hypothesis::Gps, 1.0, 7.5, 10000).unwrap();
    println!("10000 inflation {:?} last {:?}", t.elapsed(), c.last());
    let t = std::time::Instant::now();
    let _ = flattening_curve(&law, Hypothesis::Gps, 6.0, 3.0, 1000).unwrap();
    let _ = flattening_curve(&law, Hypothesis::Ps, 6.0, 3.0, 1000).unwrap();
    println!("2x1000 flatten {:?}", t.elapsed());
}
