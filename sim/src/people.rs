//! People walking through a scenario's world: a path of waypoints walked back and forth, with
//! a stance-and-swing gait (one foot planted while the other swings past it at twice the
//! walking speed), short stops where the walk turns, and way given to the robot. Each leg is a
//! circle the LiDAR sees, at the instant of each reading.
//!
//! This is the simulator's own walking model, written apart from the evaluation annex's (which
//! swings both legs sinusoidally between two points and never stops), so that a rule tuned on
//! these people is still judged on people it was not tuned on.

use perception::geometry::Point2;
use rand::Rng;

use crate::world::{Shape, World};

/// Half the distance between a person's feet across the walk, m.
pub const HALF_STANCE_M: f32 = 0.09;
/// Closest a walker comes to the LiDAR: nearer, it waits (gives way), m.
pub const GIVE_WAY_M: f32 = 0.7;
/// Longest a walker waits for the robot, s; then it walks on (round it, as people do: the
/// legs are not drawn within [`ROBOT_RADIUS_M`] of the LiDAR).
pub const MAX_WAIT_S: f32 = 1.0;
/// Legs nearer the LiDAR than this are inside the robot's body: a person stepping round it.
pub const ROBOT_RADIUS_M: f32 = 0.2;
/// Clearance of a waypoint and of the path between waypoints from walls and furniture, m.
pub const PATH_CLEARANCE_M: f32 = 0.35;

/// A person walking a path of waypoints back and forth.
#[derive(Debug, Clone, PartialEq)]
pub struct Walker {
    /// Waypoints, world frame (at least two).
    path: Vec<Point2>,
    /// Cumulative length of the path at each waypoint, m.
    at_len: Vec<f32>,
    /// Walking speed, m/s.
    pub speed: f32,
    /// Step length (one foot's footfall to the other's), m.
    pub step: f32,
    /// Leg radius, m.
    pub leg_r: f32,
    /// Reflectivity of the legs (clothes).
    pub reflectivity: f32,
    /// How long the person stands where the walk turns, s.
    pub pause_s: f32,
    /// Distance walked so far (unfolded: back and forth counted along), m.
    walked: f32,
    /// Time left standing at a turn, s.
    standing: f32,
    /// Time waited for the robot so far, s.
    waited: f32,
    /// The legs where they are now ([`Walker::legs`]): kept, since the LiDAR looks at them
    /// once per reading and they only move in [`Walker::step`].
    legs_now: [Point2; 2],
}

impl Walker {
    /// A walker on `path` (≥ 2 waypoints) starting `walked` metres into its back-and-forth.
    pub fn new(
        path: Vec<Point2>,
        speed: f32,
        leg_r: f32,
        reflectivity: f32,
        pause_s: f32,
    ) -> Walker {
        let mut at_len = vec![0.0];
        for w in path.windows(2) {
            at_len.push(at_len[at_len.len() - 1] + w[0].distance(w[1]));
        }
        let mut w = Walker {
            path,
            at_len,
            speed,
            step: 0.3 + 0.35 * speed,
            leg_r,
            reflectivity,
            pause_s,
            walked: 0.0,
            standing: 0.0,
            waited: 0.0,
            legs_now: [Point2::new(0.0, 0.0); 2],
        };
        w.walk_to(0.0);
        w
    }

    /// Sets the distance walked, and the legs with it.
    fn walk_to(&mut self, walked: f32) {
        self.walked = walked;
        self.legs_now = self.legs_at(walked);
    }

    /// Draws a walker in `world`: 2–4 waypoints with free straight paths between them, kept
    /// [`GIVE_WAY_M`] clear of `keep_clear` (the robot's start), 0.4–1.3 m/s. `None` when no
    /// such path is found in a few tries.
    pub fn draw(world: &World, rng: &mut impl Rng, keep_clear: Point2) -> Option<Walker> {
        for _ in 0..40 {
            let n = rng.random_range(2..=4);
            let mut path: Vec<Point2> = Vec::with_capacity(n);
            for _ in 0..n {
                let Some(p) = world.free_point(rng, PATH_CLEARANCE_M + 0.1) else {
                    break;
                };
                let ok = p.distance(keep_clear) > GIVE_WAY_M + 0.3
                    && path
                        .last()
                        .is_none_or(|&q| q.distance(p) > 1.0 && path_free(world, q, p, keep_clear));
                if ok {
                    path.push(p);
                }
            }
            if path.len() >= 2 {
                let speed = rng.random_range(0.4..1.3);
                let leg_r = rng.random_range(0.045..0.08);
                let refl = rng.random_range(0.2..0.7);
                let pause = rng.random_range(0.0..1.0);
                let mut w = Walker::new(path, speed, leg_r, refl, pause);
                w.walk_to(rng.random_range(0.0..w.length()));
                return Some(w);
            }
        }
        None
    }

    /// Length of the path one way, m.
    pub fn length(&self) -> f32 {
        self.at_len[self.at_len.len() - 1]
    }

    /// The point `s` metres along the back-and-forth (folded onto the path).
    fn point(&self, s: f32) -> Point2 {
        let len = self.length().max(1e-3);
        let lap = s.rem_euclid(2.0 * len);
        let u = if lap <= len { lap } else { 2.0 * len - lap };
        let k = self
            .at_len
            .partition_point(|&l| l <= u)
            .clamp(1, self.path.len() - 1);
        let (a, b) = (self.path[k - 1], self.path[k]);
        let seg = (self.at_len[k] - self.at_len[k - 1]).max(1e-6);
        let f = ((u - self.at_len[k - 1]) / seg).clamp(0.0, 1.0);
        Point2::new(a.x + (b.x - a.x) * f, a.y + (b.y - a.y) * f)
    }

    /// Where footfall `j` (at `j` steps along the walk) is planted: on the path, offset to
    /// its foot's side across the direction of the path there.
    fn foot(&self, j: i64) -> Point2 {
        let s = j as f32 * self.step;
        let c = self.point(s);
        let ahead = self.point(s + 0.05);
        let behind = self.point(s - 0.05);
        let (dx, dy) = (ahead.x - behind.x, ahead.y - behind.y);
        let n = (dx * dx + dy * dy).sqrt().max(1e-6);
        let side = if j.rem_euclid(2) == 0 { 1.0 } else { -1.0 };
        Point2::new(
            c.x - dy / n * HALF_STANCE_M * side,
            c.y + dx / n * HALF_STANCE_M * side,
        )
    }

    /// Midpoint of the person (on the path).
    pub fn centre(&self) -> Point2 {
        self.point(self.walked)
    }

    /// The two legs: the planted foot of the nearest footfall, and the other foot swinging in
    /// a straight line from the footfall before it to the one after.
    pub fn legs(&self) -> [Point2; 2] {
        self.legs_now
    }

    /// The legs after `walked` metres.
    fn legs_at(&self, walked: f32) -> [Point2; 2] {
        let x = walked / self.step;
        let j = (x + 0.5).floor() as i64;
        let u = x + 0.5 - j as f32;
        let (from, to) = (self.foot(j - 1), self.foot(j + 1));
        [
            self.foot(j),
            Point2::new(from.x + (to.x - from.x) * u, from.y + (to.y - from.y) * u),
        ]
    }

    /// Whether the walk from `s0` to `s1` passes an end of the path.
    fn turns_between(&self, s0: f32, s1: f32) -> bool {
        let len = self.length().max(1e-3);
        (s0 / len).floor() != (s1 / len).floor()
    }

    /// Moves the person on by `dt` seconds. It stands while turning at an end of its path, and
    /// waits (up to [`MAX_WAIT_S`]) while a step would bring it nearer than [`GIVE_WAY_M`] to
    /// `lidar`.
    pub fn step(&mut self, dt: f32, lidar: Point2) {
        if self.standing > 0.0 {
            self.standing -= dt;
            return;
        }
        let next = self.walked + self.speed * dt;
        let (now, then) = (self.centre(), self.point(next));
        if then.distance(lidar) < GIVE_WAY_M
            && then.distance(lidar) < now.distance(lidar)
            && self.waited < MAX_WAIT_S
        {
            self.waited += dt;
            return;
        }
        if now.distance(lidar) >= GIVE_WAY_M + 0.2 {
            self.waited = 0.0; // clear of the robot: the next meeting waits again
        }
        if self.turns_between(self.walked, next) {
            self.standing = self.pause_s;
        }
        self.walk_to(next);
    }

    /// The legs as ray-castable circles.
    pub fn leg_shapes(&self) -> [Shape; 2] {
        self.legs().map(|c| Shape::Circle { c, r: self.leg_r })
    }
}

/// Whether the straight walk `a`→`b` keeps [`PATH_CLEARANCE_M`] from walls and furniture and
/// [`GIVE_WAY_M`] from `keep_clear`.
fn path_free(world: &World, a: Point2, b: Point2, keep_clear: Point2) -> bool {
    let n = (a.distance(b) / 0.1).ceil().max(1.0) as usize;
    (0..=n).all(|i| {
        let f = i as f32 / n as f32;
        let p = Point2::new(a.x + (b.x - a.x) * f, a.y + (b.y - a.y) * f);
        world.clearance(p) >= PATH_CLEARANCE_M && p.distance(keep_clear) > GIVE_WAY_M
    })
}

#[cfg(test)]
mod test {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn straight(speed: f32) -> Walker {
        Walker::new(
            vec![Point2::new(0.0, 0.0), Point2::new(3.0, 0.0)],
            speed,
            0.06,
            0.5,
            0.0,
        )
    }

    #[test]
    fn one_foot_is_planted_while_the_other_swings() {
        let mut w = straight(1.0);
        let far = Point2::new(50.0, 50.0);
        let mut planted_moves = 0;
        let mut prev = w.legs();
        for _ in 0..200 {
            w.step(0.01, far);
            let now = w.legs();
            // Each tick, one of the legs stays put (the planted one), and nothing jumps.
            let still = now
                .iter()
                .any(|a| prev.iter().any(|b| a.distance(*b) < 1e-4));
            if !still {
                planted_moves += 1;
            }
            for a in &now {
                let moved = prev.iter().map(|b| a.distance(*b)).fold(f32::MAX, f32::min);
                assert!(moved < 0.05, "a leg jumped {moved} m");
            }
            prev = now;
        }
        // Only the ticks where the feet change roles (once a step) see both move.
        assert!(
            planted_moves <= 8,
            "{planted_moves} ticks with no foot planted"
        );
    }

    #[test]
    fn it_walks_back_and_forth_and_stops_to_turn() {
        let mut w = straight(1.0);
        w.pause_s = 0.5;
        let far = Point2::new(50.0, 50.0);
        let mut xs = Vec::new();
        for _ in 0..800 {
            w.step(0.01, far);
            xs.push(w.centre().x);
        }
        let max = xs.iter().copied().fold(f32::MIN, f32::max);
        assert!(max > 2.95 && max <= 3.0 + 1e-4, "{max}");
        // After the far end it comes back, having stood there about 0.5 s.
        let at_end = xs.iter().filter(|&&x| x > 2.99).count();
        assert!((45..=60).contains(&at_end), "{at_end} ticks at the end");
        assert!(xs[799] < 2.0, "{}", xs[799]);
    }

    #[test]
    fn it_gives_way_to_the_robot_for_a_while() {
        let mut w = straight(1.0);
        let robot = Point2::new(2.0, 0.0);
        let mut waited = 0;
        for _ in 0..400 {
            w.step(0.01, robot);
            if w.centre().distance(robot) < GIVE_WAY_M - 0.02 {
                break;
            }
            waited += 1;
        }
        // 1.3 m to walk at 1 m/s, then a second's wait, then on past the robot.
        assert!((225..=240).contains(&waited), "{waited} ticks");
    }

    #[test]
    fn drawn_walkers_are_seeded_and_keep_clear() {
        let world = World::random_room(3);
        let start = Point2::new(world.floor[0].0.x + 1.0, world.floor[0].0.y + 1.0);
        let a = Walker::draw(&world, &mut ChaCha8Rng::seed_from_u64(5), start);
        let b = Walker::draw(&world, &mut ChaCha8Rng::seed_from_u64(5), start);
        assert_eq!(a, b);
        let w = a.expect("a walker fits in a random room");
        assert!(w.length() > 1.0);
        for p in &w.path {
            assert!(world.clearance(*p) >= PATH_CLEARANCE_M);
        }
    }
}
