use relume::atmosphere::study::*;
use relume::atmosphere::*;
#[test]
fn probe() {
    let atm = Atmosphere::earth();
    let t = std::time::Instant::now();
    let rows = error_vs_elevation(&atm, &[90.0, 60.0, 30.0, 15.0, 10.0, 5.0, 2.0, 0.0, -2.0], &Views::default());
    println!("{}", markdown(&rows));
    for lim in [0.1, 0.2] {
        println!("lim {lim}: fog_vs_single {:?} att_vs_single {:?} fog {:?} hill_ap {:?} hill_sky {:?}",
          lowest_within(&rows, |r| r.fog_vs_single, lim), lowest_within(&rows, |r| r.fog_attenuated_vs_single, lim),
          lowest_within(&rows, |r| r.fog, lim), lowest_within(&rows, |r| r.hillaire_aerial, lim), lowest_within(&rows, |r| r.hillaire_sky, lim));
    }
    println!("{:?}", t.elapsed());
}
