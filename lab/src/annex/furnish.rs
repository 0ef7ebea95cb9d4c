//! Furnishing an annex plan: furniture in the variants the study's world does not have (office
//! chairs on a five-star base, round tables on a pedestal or three legs, panel-end desks),
//! placed against walls (a box touching one, a desk backed to one with its chair tucked in)
//! or in the open; clutter (shelves along walls, pillars, bins); people walking.

use perception::class::ObjectClass;
use perception::geometry::Point2;
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use sim::world::Shape;

use super::plan::{Face, Owner, Piece, Plan, Prim, Walker, offset, outline, rect, seg};

fn legs(c: Point2, hx: f32, hy: f32, yaw: f32, r: f32) -> Vec<Shape> {
    rect(c, hx - r, hy - r, yaw)
        .into_iter()
        .map(|c| Shape::Circle { c, r })
        .collect()
}

/// A random piece of `class` at the origin, facing +x.
fn make_piece(rng: &mut ChaCha8Rng, class: ObjectClass) -> Piece {
    let (c, yaw) = (Point2::new(0.0, 0.0), 0.0f32);
    let refl = rng.random_range(0.2..0.9f32);
    let (footprint, shapes, what) = match class {
        ObjectClass::Chair if rng.random_bool(0.5) => {
            // Office chair: a gas column and five spokes to casters.
            let arm = rng.random_range(0.27..0.34f32);
            let mut s = vec![Shape::Circle { c, r: 0.03 }];
            for k in 0..5 {
                let a = yaw + k as f32 * core::f32::consts::TAU / 5.0;
                let e = Point2::new(c.x + arm * a.cos(), c.y + arm * a.sin());
                s.push(seg(
                    Point2::new(c.x + 0.04 * a.cos(), c.y + 0.04 * a.sin()),
                    e,
                ));
                s.push(Shape::Circle { c: e, r: 0.025 });
            }
            (rect(c, arm + 0.03, arm + 0.03, yaw), s, "office chair")
        }
        ObjectClass::Chair => {
            let hs = rng.random_range(0.19..0.25f32);
            let r = rng.random_range(0.012..0.022f32);
            (
                rect(c, hs, hs, yaw),
                legs(c, hs, hs, yaw, r),
                "four-legged chair",
            )
        }
        ObjectClass::Desk if rng.random_bool(0.3) => {
            // Round table: a pedestal, or three legs.
            let rad = rng.random_range(0.35..0.5f32);
            let s = if rng.random_bool(0.5) {
                vec![Shape::Circle {
                    c,
                    r: rng.random_range(0.04..0.07),
                }]
            } else {
                (0..3)
                    .map(|k| {
                        let a = yaw + k as f32 * core::f32::consts::TAU / 3.0;
                        Shape::Circle {
                            c: Point2::new(
                                c.x + (rad - 0.05) * a.cos(),
                                c.y + (rad - 0.05) * a.sin(),
                            ),
                            r: 0.02,
                        }
                    })
                    .collect()
            };
            (rect(c, rad, rad, yaw), s, "round table")
        }
        ObjectClass::Desk => {
            let (hl, hd) = (rng.random_range(0.6..0.9f32), rng.random_range(0.3..0.4f32));
            if rng.random_bool(0.35) {
                // Panel ends instead of legs.
                let fp = rect(c, hl, hd, yaw);
                let s = vec![seg(fp[0], fp[3]), seg(fp[1], fp[2])];
                (fp, s, "panel-end desk")
            } else {
                let r = rng.random_range(0.015..0.03f32);
                (
                    rect(c, hl, hd, yaw),
                    legs(c, hl, hd, yaw, r),
                    "four-legged desk",
                )
            }
        }
        _ => {
            let (hl, hd) = (
                rng.random_range(0.15..0.4f32),
                rng.random_range(0.15..0.3f32),
            );
            let fp = rect(c, hl, hd, yaw);
            (fp.clone(), outline(&fp), "box")
        }
    };
    Piece {
        class,
        footprint,
        shapes,
        refl,
        what: what.into(),
        against_wall: false,
    }
}

/// `piece` turned by `yaw` and moved to `c`.
fn place(mut piece: Piece, c: Point2, yaw: f32) -> Piece {
    let (s, co) = yaw.sin_cos();
    let tf = |p: Point2| Point2::new(c.x + co * p.x - s * p.y, c.y + s * p.x + co * p.y);
    for p in &mut piece.footprint {
        *p = tf(*p);
    }
    for sh in &mut piece.shapes {
        *sh = match *sh {
            Shape::Segment { a, b } => Shape::Segment { a: tf(a), b: tf(b) },
            Shape::Circle { c, r } => Shape::Circle { c: tf(c), r },
        };
    }
    piece
}

pub(super) fn furnish(plan: &mut Plan, faces: &[Face], rng: &mut ChaCha8Rng) {
    let area: f32 = plan
        .floor
        .iter()
        .map(|(a, b)| (b.x - a.x) * (b.y - a.y))
        .sum();
    let target = ((area / 7.0) as usize).clamp(3, 12);
    let mut tries = 0;
    while plan.pieces.len() < target && tries < 400 {
        tries += 1;
        let class =
            [ObjectClass::Chair, ObjectClass::Desk, ObjectClass::Box][rng.random_range(0..3)];
        if rng.random_bool(0.45) {
            // Against a wall: backed to a face, 0–3 cm off it.
            let f = faces[rng.random_range(0..faces.len())];
            if f.len() < 2.0 {
                continue;
            }
            let s = rng.random_range(0.5..f.len() - 0.5);
            let n = f.inward();
            let yaw = f.dir().y.atan2(f.dir().x);
            let probe = make_piece(rng, class);
            let depth = probe
                .footprint
                .iter()
                .map(|q| q.y.abs())
                .fold(0.0, f32::max);
            let c = offset(f.at(s), n, depth + rng.random_range(0.0..0.03));
            let mut piece = place(probe, c, yaw);
            piece.against_wall = true;
            piece.what += " against a wall";
            if !plan.fits(&piece.footprint, 0.5) {
                continue;
            }
            let tuck = class == ObjectClass::Desk
                && piece.what.starts_with("four")
                && rng.random_bool(0.6);
            plan.pieces.push(piece);
            if tuck {
                // A chair tucked at the desk: its centre 0.1–0.2 m inside the desk's front edge.
                let along = rng.random_range(-0.3..0.3f32);
                let cc = offset(
                    offset(c, f.dir(), along),
                    n,
                    depth - rng.random_range(0.1..0.2),
                );
                let chair = make_piece(rng, ObjectClass::Chair);
                let mut chair = place(chair, cc, yaw + rng.random_range(-0.3..0.3));
                chair.what += " tucked at a desk";
                plan.pieces.push(chair);
            }
        } else {
            let Some(c) = plan.free_point(rng, 0.6) else {
                continue;
            };
            let piece = place(
                make_piece(rng, class),
                c,
                rng.random_range(0.0..core::f32::consts::TAU),
            );
            if plan.fits(&piece.footprint, 0.6) {
                plan.pieces.push(piece);
            }
        }
    }
    // Clutter: shelves along walls, pillars, bins.
    let n_clutter = rng.random_range(1..=5usize);
    let mut tries = 0;
    while plan.clutter.len() < n_clutter && tries < 200 {
        tries += 1;
        let k = rng.random_range(0..4);
        let refl = rng.random_range(0.2..0.9f32);
        let (c, shapes, what): (Point2, Vec<Shape>, &str) = match k {
            0 => {
                let f = faces[rng.random_range(0..faces.len())];
                let hl = rng.random_range(0.4..0.9f32);
                if f.len() < 2.0 * hl + 0.4 {
                    continue;
                }
                let s = rng.random_range(hl + 0.1..f.len() - hl - 0.1);
                let hd = rng.random_range(0.15..0.2f32);
                let c = offset(f.at(s), f.inward(), hd + 0.01);
                let fp = rect(c, hl, hd, f.dir().y.atan2(f.dir().x));
                (c, outline(&fp), "shelf")
            }
            1 => {
                let Some(c) = plan.free_point(rng, 0.5) else {
                    continue;
                };
                let h = rng.random_range(0.15..0.25f32);
                (
                    c,
                    outline(&rect(c, h, h, rng.random_range(0.0..1.5))),
                    "square pillar",
                )
            }
            2 => {
                let Some(c) = plan.free_point(rng, 0.5) else {
                    continue;
                };
                (
                    c,
                    vec![Shape::Circle {
                        c,
                        r: rng.random_range(0.15..0.3),
                    }],
                    "round pillar",
                )
            }
            _ => {
                let Some(c) = plan.free_point(rng, 0.4) else {
                    continue;
                };
                (
                    c,
                    vec![Shape::Circle {
                        c,
                        r: rng.random_range(0.11..0.2),
                    }],
                    "bin",
                )
            }
        };
        if plan
            .pieces
            .iter()
            .any(|p| p.centre().distance(c) < p.radius() + 0.7)
            || plan.clutter.iter().any(|(q, _)| q.distance(c) < 1.0)
            || plan.doors.iter().any(|d| d.centre.distance(c) < 1.2)
        {
            continue;
        }
        let i = plan.clutter.len();
        plan.fixed.extend(shapes.into_iter().map(|shape| Prim {
            shape,
            owner: Owner::Clutter(i),
            refl,
        }));
        plan.clutter.push((c, what.into()));
    }
    // People: up to two, walking between free points.
    for _ in 0..rng.random_range(0..=2) {
        for _ in 0..30 {
            let (Some(a), Some(b)) = (plan.free_point(rng, 0.45), plan.free_point(rng, 0.45))
            else {
                continue;
            };
            if a.distance(b) > 1.5 && plan.path_free(a, b, 0.35) {
                plan.walkers.push(Walker {
                    a,
                    b,
                    speed: rng.random_range(0.5..1.1),
                    leg_r: rng.random_range(0.05..0.07),
                    phase: rng.random_range(0.0..10.0),
                });
                break;
            }
        }
    }
}
