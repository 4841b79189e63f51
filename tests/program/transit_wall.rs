//! The transit check's wall after any number of beads (issue 21):
//! [`WallBeads::wall`] answers from blocks of beads whose segment trees are
//! built once, and must give the very answers of one segment tree of all
//! the first beads ([`wall_of`], the check as it was before the blocks) —
//! the same clearance, to the bit, and the same clear/not-clear verdict —
//! on the beads of sample parts, for torch poses clear of the wall and
//! inside it, and along the real arc-off joint moves of a program.

use waam_slicer::io::part_file::read_part_file;
use waam_slicer::math::{Point3, Vector3};
use waam_slicer::path::slice;
use waam_slicer::program::transit::{joint_move_clearance, wall_of, TransitWall, WallBeads};
use waam_slicer::toolaxis::collision::Torch;

use crate::fixture::{bead_positions, part_carried, program};

/// The layers of a sample part in `parts/` at `delta_mm`, one bead each
/// (part frame, mm).
fn beads(part: &str, delta_mm: f64) -> Vec<Vec<Point3>> {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("parts")
        .join(part);
    let part = read_part_file(&p).unwrap_or_else(|e| panic!("{e}"));
    let mut so = part.slice_options();
    so.delta_mm = delta_mm;
    let path = slice(&part.tube, &part.substrate, &so).unwrap_or_else(|e| panic!("{e}"));
    path.layers
        .iter()
        .map(|l| l.points.iter().map(|p| p.position).collect())
        .collect()
}

/// A small deterministic generator (64-bit LCG, top 53 bits), in [0, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn unit(&mut self) -> Vector3 {
        loop {
            let v = Vector3::new(
                2.0 * self.next() - 1.0,
                2.0 * self.next() - 1.0,
                2.0 * self.next() - 1.0,
            );
            let n = v.norm();
            if n > 0.1 && n <= 1.0 {
                return v / n;
            }
        }
    }
}

/// Compares the blocks' answers with one tree's for the first `n` beads,
/// every `n`, at torch poses near the last beads laid; returns how many
/// poses were (colliding, clear).
fn compare(beads: &[Vec<Point3>], radius_mm: f64, poses_per_wall: usize) -> (usize, usize) {
    let torch = Torch::new(&Default::default()).unwrap();
    let mut blocks = WallBeads::default();
    let mut rng = Lcg(0x5eed ^ beads.len() as u64);
    let (mut colliding, mut clear) = (0, 0);
    for n in 1..=beads.len() {
        blocks.push(&beads[n - 1]);
        let one_tree = wall_of(beads[..n].iter().map(Vec::as_slice), radius_mm);
        let prefix = blocks.wall(n, radius_mm);
        assert_eq!(TransitWall::is_empty(&prefix), one_tree.is_empty());
        for _ in 0..poses_per_wall {
            // the tip near a point of one of the last three beads (or any
            // earlier one), the axis anywhere but mostly upwards
            let b = if rng.next() < 0.8 {
                n - 1 - ((rng.next() * 3.0) as usize).min(n - 1)
            } else {
                ((rng.next() * n as f64) as usize).min(n - 1)
            };
            let bead = &beads[b];
            let p = bead[((rng.next() * bead.len() as f64) as usize).min(bead.len() - 1)];
            let tip = p + rng.unit() * (25.0 * rng.next());
            let mut axis = rng.unit();
            if rng.next() < 0.7 {
                axis.z = axis.z.abs();
            }
            let expected = one_tree.clearance(&torch, &tip, &axis).unwrap();
            let got = prefix.clearance(&torch, &tip, &axis).unwrap();
            assert_eq!(
                got.to_bits(),
                expected.to_bits(),
                "{n} beads, tip {tip:?}, axis {axis:?}: blocks {got} vs one tree {expected}"
            );
            for margin in [0.0, 1.0, 5.0] {
                assert_eq!(
                    prefix.is_clear(&torch, &tip, &axis, margin).unwrap(),
                    one_tree.is_clear(&torch, &tip, &axis, margin).unwrap(),
                    "{n} beads, tip {tip:?}, axis {axis:?}, margin {margin}: clearance {expected}"
                );
            }
            if expected <= 0.0 {
                colliding += 1;
            } else {
                clear += 1;
            }
        }
    }
    (colliding, clear)
}

#[test]
fn the_blocks_answer_as_one_tree_on_the_hemisphere_beads() {
    // 22 layers of 500 points: every bead decimated (the capsules grown),
    // walls of 1 to 22 beads (1 to 3 blocks of 1 to 16 beads)
    let beads = beads("hemisphere.toml", 2.0);
    assert!(beads.len() >= 20, "{} layers", beads.len());
    assert!(beads.iter().all(|b| b.len() > 256));
    for radius in [2.0, 0.0] {
        let (colliding, clear) = compare(&beads, radius, 60);
        assert!(
            colliding > 100 && clear > 100,
            "radius {radius}: {colliding} colliding, {clear} clear poses"
        );
    }
}

#[test]
fn the_blocks_answer_as_one_tree_on_the_quarter_torus_beads() {
    let beads = beads("quarter-torus.toml", 5.0);
    assert!(beads.len() >= 7, "{} layers", beads.len());
    let (colliding, clear) = compare(&beads, 2.0, 150);
    assert!(
        colliding > 50 && clear > 50,
        "{colliding} colliding, {clear} clear poses"
    );
}

#[test]
fn beads_of_one_point_are_no_wall_in_either() {
    let one = [Point3::new(0.0, 0.0, 1.0)];
    let two = [Point3::new(-50.0, 0.0, 1.0), Point3::new(50.0, 0.0, 1.0)];
    let mut blocks = WallBeads::default();
    blocks.push(&one);
    blocks.push(&one);
    blocks.push(&one);
    assert!(TransitWall::is_empty(&blocks.wall(3, 2.0)));
    assert!(wall_of([&one[..], &one, &one], 2.0).is_empty());
    blocks.push(&two);
    let prefix = blocks.wall(4, 2.0);
    assert!(!TransitWall::is_empty(&prefix));
    // the torch standing on the segment: inside the capsule, clearance −r
    let torch = Torch::new(&Default::default()).unwrap();
    let c = prefix
        .clearance(&torch, &Point3::new(0.0, 0.0, 1.0), &Vector3::z())
        .unwrap();
    let expected = wall_of([&one[..], &one, &one, &two], 2.0)
        .clearance(&torch, &Point3::new(0.0, 0.0, 1.0), &Vector3::z())
        .unwrap();
    assert_eq!(c, expected);
    // the torch far away: positive in both, and the same
    let far = Point3::new(0.0, 300.0, 1.0);
    let c = prefix.clearance(&torch, &far, &Vector3::z()).unwrap();
    assert!(c > 200.0, "{c}");
    assert_eq!(
        c,
        wall_of([&one[..], &one, &one, &two], 2.0)
            .clearance(&torch, &far, &Vector3::z())
            .unwrap()
    );
}

#[test]
fn the_arc_off_moves_of_a_program_meet_the_wall_alike() {
    // the joint moves from the end of every bead of a 7-layer program to
    // the joints of layer 0's first point (most of them pass through the
    // next layers, see `setup.rs`) and to the next bead's first point
    let cell = part_carried();
    let (prog, _) = program(&cell, 0..7, 12);
    let beads = bead_positions(&prog, 7);
    let torch = Torch::new(&Default::default()).unwrap();
    let q0 = prog.bead_points().next().unwrap().joints;
    let mut blocks = WallBeads::default();
    let mut colliding = 0;
    for (k, bead) in beads.iter().enumerate() {
        blocks.push(bead);
        let one_tree = wall_of(beads[..=k].iter().map(Vec::as_slice), 2.0);
        let prefix = blocks.wall(k + 1, 2.0);
        let last = prog
            .bead_points()
            .filter(|p| p.layer == k)
            .last()
            .unwrap()
            .joints;
        let mut targets = vec![q0];
        if let Some(next) = prog.bead_points().find(|p| p.layer == k + 1) {
            targets.push(next.joints);
        }
        for q in targets {
            let a =
                joint_move_clearance(&cell, &one_tree, &torch, (&last, None), (&q, None)).unwrap();
            let b =
                joint_move_clearance(&cell, &prefix, &torch, (&last, None), (&q, None)).unwrap();
            assert_eq!(a, b, "bead {k}");
            colliding += usize::from(a.min_clearance_mm <= 0.0);
        }
    }
    assert!(colliding >= 3, "{colliding} colliding moves");
}

/// The transit's depth in words (`transit::intrusion`): the clearance is
/// measured from the torch to the bead's centreline, less the bead's
/// radius, so a torch pushed 1 mm into a bead (tip 1 mm inside the capsule,
/// axis across it) reads 1 mm, and a torch through the bead (its tip below
/// the centreline) reads the radius itself however deep it goes: that is
/// said as "through the deposited wall", not as a depth (before, the elbow's
/// and the S-bend's refused transits read "2.0 mm into the deposited wall").
#[test]
fn a_torch_through_the_bead_is_said_so_not_given_the_radius_as_its_depth() {
    use waam_slicer::program::transit::intrusion;
    let radius = 2.0;
    // one straight bead along X at the origin
    let bead: Vec<Point3> = (0..=20).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
    let wall = wall_of([bead.as_slice()], radius);
    let torch = Torch::new(&Default::default()).unwrap();
    let up = Vector3::z();
    // the torch's lowest point lies `stand` above the wire's tip (its
    // point): measured with the tip on the centreline
    let stand = wall
        .clearance(&torch, &Point3::new(10.0, 0.0, 0.0), &up)
        .unwrap()
        + radius;
    assert!(stand > 0.0, "{stand}");
    // lowest point 1 mm inside the capsule's top: 1 mm deep
    let c = wall
        .clearance(&torch, &Point3::new(10.0, 0.0, 1.0 - stand), &up)
        .unwrap();
    assert!((c + 1.0).abs() < 1e-9, "{c}");
    assert_eq!(intrusion(c, radius), "1.0 mm into the deposited wall");
    // lowest point 5 and 10 mm below the centreline: the same -radius
    for z in [-5.0, -10.0] {
        let c = wall
            .clearance(&torch, &Point3::new(10.0, 0.0, z - stand), &up)
            .unwrap();
        assert!((c + radius).abs() < 1e-9, "{z}: {c}");
        assert_eq!(
            intrusion(c, radius),
            "through the deposited wall (the torch crosses a bead's centreline)"
        );
    }
}
