//! The parallel contact stage (feature `parallel`) gives the same bits as the serial one.
#![cfg(feature = "parallel")]

use grainlab::build_with;
use grainlab::scene::{Grains, TangentialSpec};
use grainlab::scenes::shear;

#[test]
fn two_threads_give_the_same_bits_as_one() {
    // The contact forces are gathered per grain in pair order and the energy terms in
    // pair order, so floating-point sums happen in the serial order: not "close", equal.
    for tangential in [TangentialSpec::TotalDisplacement, TangentialSpec::IncrementalForce] {
        let mut s = shear();
        s.model.tangential = tangential;
        if let Grains::Pack(p) = &mut s.grains {
            p.count = 3000;
            p.x = [0.0, 0.12];
        }
        s.domain.periodic_x = Some([0.0, 0.12]);
        let mut a = build_with(&s, 1).unwrap();
        let mut b = build_with(&s, 2).unwrap();
        assert!(b.explain().contains("parallel, 2 threads"), "{}", b.explain());
        for _ in 0..2000 {
            a.engine.step().unwrap();
            b.engine.step().unwrap();
        }
        let (pa, pb) = (a.engine.particles(), b.engine.particles());
        assert!(a.engine.touching() > 1000, "a dense, sheared packing: {}", a.engine.touching());
        for i in 0..pa.len() {
            assert_eq!(pa.x[i].x.to_bits(), pb.x[i].x.to_bits(), "{tangential:?} grain {i}");
            assert_eq!(pa.x[i].y.to_bits(), pb.x[i].y.to_bits(), "{tangential:?} grain {i}");
            assert_eq!(pa.v[i].x.to_bits(), pb.v[i].x.to_bits(), "{tangential:?} grain {i}");
            assert_eq!(pa.omega[i].to_bits(), pb.omega[i].to_bits(), "{tangential:?} grain {i}");
        }
        let (ea, eb) = (a.engine.energy_row(), b.engine.energy_row());
        assert_eq!(ea.residual_j.to_bits(), eb.residual_j.to_bits());
        assert_eq!(ea.tangential_model_work_j.to_bits(), eb.tangential_model_work_j.to_bits());
    }
}
