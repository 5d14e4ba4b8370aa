//! The lab's nodes wired as a recording graph would wire them:
//! tribometer → display → force sensor, acyclic, through a real plan.

use crate::lab::profile::{LabProfile, G};
use crate::lab::testutil::{mean, prbs};
use evflow_engine::graph::parse_graph;
use evflow_engine::harness::{FEED, TAP};
use evflow_engine::{check, Plan, PlanOptions, Registry};
use std::path::Path;

fn graph(u: &[f64], extra: &str) -> String {
    let list: Vec<String> = u.iter().map(|x| format!("{x:.1}")).collect();
    format!(
        r#"[graph]
format = 1
name = "lab-chain"
rate = 1000
connections = [
  "trib.velocity -> display.velocity",
  "trib.load -> display.load",
  "act.out -> display.u",
  "display.force -> sensor.surface_force",
  "trib.velocity -> sensor.velocity",
  "sensor.force -> out.in",
  "trib.position -> pos.in",
]
[nodes.trib]
type = "sim.tribometer"
speed = 5.0
mass = 85.0
passes = 2
{extra}
[nodes.act]
type = "harness.feed"
rate = 1000
values = [{}]
[nodes.display]
type = "sim.display"
noise = 0.0
[nodes.sensor]
type = "sim.forcesensor"
noise = 0.0
[nodes.out]
type = "harness.tap"
[nodes.pos]
type = "harness.tap"
"#,
        list.join(",")
    )
}

fn run(text: &str, ticks: usize) -> (Vec<f64>, Vec<f64>) {
    let mut reg = Registry::new();
    for s in crate::lab::SPECS {
        reg.add(s);
    }
    reg.add(&FEED).add(&TAP);
    let g = parse_graph(Path::new("chain.toml"), text).unwrap();
    let checked = check(&g, &reg, &[]).unwrap_or_else(|e| panic!("{e}"));
    let opts = PlanOptions {
        max_block: 64,
        seed: Some(3),
        base_dir: None,
        timing: false,
        out_dir: None,
        mode: evflow_engine::RunMode::Offline,
        check_only: false,
    };
    let mut plan = Plan::build(&checked, &opts).unwrap();
    let (mut force, mut pos) = (Vec::new(), Vec::new());
    let mut done = 0;
    while done < ticks {
        let n = 64.min(ticks - done);
        plan.step(n).unwrap();
        force.extend_from_slice(plan.output("sensor", 0).unwrap());
        pos.extend_from_slice(plan.output("trib", 0).unwrap());
        done += n;
    }
    plan.finish().unwrap();
    (force, pos)
}

#[test]
fn tribometer_display_and_sensor_form_an_acyclic_recording_chain() {
    // Two passes of 8 cm at 5 cm/s: 2 × (0.5 s dwell + 1.65 s) + 0.5 s.
    let ticks = 4800;
    let (force, pos) = run(&graph(&vec![0.0; ticks], ""), ticks);
    assert!(force.iter().all(|f| f.is_finite()));
    assert!((pos.iter().cloned().fold(0.0, f64::max) - 0.08).abs() < 1e-12);
    // Cruise of the right pass (0.55–2.1 s) and of the left (2.7–4.25 s):
    // μ_k·(m g ± F_b) plus the viscous term and the sensor's direction bias.
    let p = LabProfile::default();
    let (fr, fb, sen) = (&p.display.friction, p.tribometer.bearing_friction_n, &p.sensor);
    let mg = 0.085 * G;
    let want_r = fr.mu_kinetic * (mg + fb) + fr.viscous * 0.05 + sen.bias_right_n;
    let want_l = -(fr.mu_kinetic * (mg - fb) + fr.viscous * 0.05) + sen.bias_left_n;
    let (r, l) = (mean(&force[800..2000]), mean(&force[2900..4100]));
    // The electrostatic force of the amplifier offset adds a little friction.
    assert!((r - want_r).abs() < 0.01, "right {r} vs {want_r}");
    assert!((l - want_l).abs() < 0.01, "left {l} vs {want_l}");
}

#[test]
fn prbs_actuation_shows_through_the_whole_chain() {
    let ticks = 4800;
    let u = prbs(ticks, 1.0);
    let (on, _) = run(&graph(&u, ""), ticks);
    let (off, _) = run(&graph(&vec![0.0; ticks], ""), ticks);
    let d: Vec<f64> = on.iter().zip(&off).map(|(a, b)| a - b).collect();
    assert!(mean(&d[800..2000]) > 0.03, "PRBS raises the mean friction: {}", mean(&d[800..2000]));
    // During the dwell the pen is stuck: actuation changes nothing measurable.
    let still = d[100..450].iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(still < 1e-3, "stuck pen: {still}");
}
