//! `evflow report mesh`: the fidelity of mesh-gradient rendering — rendered
//! F^sq against the analytic gradient of the Gaussian scene for mesh
//! resolutions from coarse to fine, against run time (a table and a
//! work-precision PNG), one scan line drawn rendered against analytic, and
//! edge detection on a CAD mesh against its dihedral angles.

use anyhow::{Context, Result};
use evflow_nodes::mesh::fidelity::{edge_fidelity, gradient_fidelity, line_trace, GradientRow, ScanPlan};
use evflow_nodes::mesh::formats::load_file;
use evflow_tools::plot::{write_png, Plot, Series};
use std::path::PathBuf;

/// Arguments of `evflow report mesh`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Folder for the PNG figures.
    #[arg(long, default_value = ".")]
    out: PathBuf,
    /// Gaussian scene configuration (0B4H … 4B0H).
    #[arg(long, default_value = "2B2H")]
    config: String,
    /// Grid cells per 6 cm object side, coarse to fine.
    #[arg(long, value_delimiter = ',', default_value = "4,8,16,32,64,128,256,512")]
    resolutions: Vec<usize>,
    /// A mesh with sharp edges for the edge report (units taken as cm): .obj,
    /// .stl, .ply, .gltf or .glb.
    #[arg(long, default_value = "../shared/data/meshes/fandisk.obj")]
    edges_mesh: PathBuf,
    /// The edge mesh's axis that points up, toward the viewer (x, y, z, -x, -y, -z).
    #[arg(long, default_value = "z", allow_hyphen_values = true)]
    up: String,
}

/// Turns the mesh so that axis `up` points along +z (a proper rotation).
fn turn(p: [f64; 3], up: &str) -> Result<[f64; 3]> {
    let [x, y, z] = p;
    Ok(match up {
        "x" => [y, z, x],
        "y" => [z, x, y],
        "z" => [x, y, z],
        "-x" => [-y, z, -x],
        "-y" => [x, z, -y],
        "-z" => [x, -y, -z],
        other => anyhow::bail!("--up {other}: expected x, y, z, -x, -y or -z"),
    })
}

/// Runs `evflow report mesh`.
pub fn main(a: Args) -> Result<()> {
    std::fs::create_dir_all(&a.out).with_context(|| format!("{}: cannot create", a.out.display()))?;
    let plan = ScanPlan::standard();
    println!(
        "Gaussian scene {} — {} directions × {} lines of {} cm at {} cm/s, {} Hz, min_step {} cm",
        a.config,
        plan.directions.len(),
        plan.offsets.len(),
        plan.length,
        plan.speed,
        plan.rate,
        plan.min_step
    );
    let rows = gradient_fidelity(&a.config, &a.resolutions, &plan);
    print_gradient_table(&rows);
    gradient_figures(&a, &rows, &plan)?;
    if a.edges_mesh.exists() {
        edge_report(&a)?;
    } else {
        println!("\n(no edge report: {} not found; pass --edges-mesh)", a.edges_mesh.display());
    }
    Ok(())
}

/// The gradient's fidelity and cost per resolution, as a Markdown table.
fn print_gradient_table(rows: &[GradientRow]) {
    println!("\n| cells/side | triangles | BVH build ms | µs/tick secant | µs/tick normal | RMS F^sq secant | RMS F^sq normal | RMS tan α secant | RMS tan α normal |");
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for r in rows {
        println!(
            "| {} | {} | {:.2} | {:.3} | {:.3} | {:.4} | {:.4} | {:.4} | {:.4} |",
            r.resolution,
            r.triangles,
            r.build_ms,
            r.tick_us_secant,
            r.tick_us_normal,
            r.rms_fsq_secant,
            r.rms_fsq_normal,
            r.rms_slope_secant,
            r.rms_slope_normal
        );
    }
}

/// The work-precision and resolution figures, and F^sq along one line
/// through two bumps.
fn gradient_figures(a: &Args, rows: &[GradientRow], plan: &ScanPlan) -> Result<()> {
    let wp = Plot {
        title: format!("Mesh gradient: error against run time (Gaussian {})", a.config),
        x_label: "ray cast + estimate per tick (µs)".into(),
        y_label: "RMS error of F^sq (√N)".into(),
        log_x: true,
        log_y: true,
        series: vec![
            Series::line_points(
                "secant (Eq. 4.1)",
                rows.iter().map(|r| (r.tick_us_secant, r.rms_fsq_secant)).collect(),
            ),
            Series::line_points("triangle normal", rows.iter().map(|r| (r.tick_us_normal, r.rms_fsq_normal)).collect()),
        ],
        ..Default::default()
    };
    report_png(&wp, &a.out.join("mesh-gradient-work-precision.png"))?;
    let res = Plot {
        title: format!("Mesh gradient: error against resolution (Gaussian {})", a.config),
        x_label: "triangles".into(),
        y_label: "RMS error of tan α".into(),
        log_x: true,
        log_y: true,
        series: vec![
            Series::line_points("secant", rows.iter().map(|r| (r.triangles as f64, r.rms_slope_secant)).collect()),
            Series::line_points(
                "triangle normal",
                rows.iter().map(|r| (r.triangles as f64, r.rms_slope_normal)).collect(),
            ),
        ],
        ..Default::default()
    };
    report_png(&res, &a.out.join("mesh-gradient-resolution.png"))?;
    let coarse = a.resolutions.iter().copied().find(|&r| r >= 8).unwrap_or(8);
    let t = line_trace("4B0H", coarse, 0.0, 3.0, plan);
    let line = Plot {
        title: format!("F^sq along y = 3 cm through two bumps, {coarse} cells/side"),
        x_label: "position along the line (cm)".into(),
        y_label: "F^sq (√N)".into(),
        log_x: false,
        log_y: false,
        series: vec![
            Series::line("analytic", t.iter().map(|r| (r[0], r[1])).collect()),
            Series::line("secant", t.iter().map(|r| (r[0], r[2])).collect()),
            Series::line("triangle normal", t.iter().map(|r| (r[0], r[3])).collect()),
        ],
        ..Default::default()
    };
    report_png(&line, &a.out.join("mesh-fsq-line.png"))?;
    Ok(())
}

/// Edge detection on the `--edges-mesh` against its dihedral angles.
fn edge_report(a: &Args) -> Result<()> {
    let m = load_file(&a.edges_mesh, 0.0).map_err(|e| anyhow::anyhow!("{e}"))?;
    let turned: Vec<[f64; 3]> = m.vertices.iter().map(|&p| turn(p, &a.up)).collect::<Result<_>>()?;
    let m = evflow_nodes::mesh::Mesh::new(turned, m.triangles.clone(), 0.0);
    let b = m.bounds();
    let ext = (b.max[0] - b.min[0]).max(b.max[1] - b.min[1]);
    let plan = ScanPlan {
        offsets: (-4..=4).map(|k| k as f64 * ext / 10.0).collect(),
        length: 1.2 * ext,
        ..ScanPlan::standard()
    };
    println!(
        "\nEdges: {} (up: {}, {} triangles), {} directions × {} lines, sharp = θ < 135° (Fig. 4.4), max_angle 160°",
        a.edges_mesh.display(),
        a.up,
        m.triangles.len(),
        plan.directions.len(),
        plan.offsets.len()
    );
    let f = edge_fidelity(&m, b.min[2], &plan, 135.0, 160.0);
    println!("\n| quantity | value |\n|---|---:|");
    for (k, v) in [
        ("θ_min of the mesh (°)", format!("{:.2}", f.theta_min)),
        ("consistently oriented interior edges", format!("{:.4}", f.oriented_fraction)),
        ("ticks changing triangle, resolved to mesh edges", f.resolved_crossings.to_string()),
        ("  of them skipping triangles (several edges in one tick)", f.multi_edge_crossings.to_string()),
        ("ticks changing triangle, unresolved", f.unresolved_crossings.to_string()),
        ("sharp crossings (truth, θ < 135°)", f.sharp_truth.to_string()),
        ("true positives", f.true_positives.to_string()),
        ("false positives", f.false_positives.to_string()),
        ("false negatives", f.false_negatives.to_string()),
        ("detections on unresolved ticks", f.unverified_detections.to_string()),
        ("RMS θ error of true positives (°)", format!("{:.3}", f.theta_rms_error)),
        ("max θ error of true positives (°)", format!("{:.3}", f.theta_max_error)),
    ] {
        println!("| {k} | {v} |");
    }
    Ok(())
}

fn report_png(p: &Plot, path: &std::path::Path) -> Result<()> {
    let w = write_png(p, path).map_err(|e| anyhow::anyhow!("{e}"))?;
    let note = if w.labelled { "" } else { " (no font found: drawn without text)" };
    println!("wrote {}{note}", w.path.display());
    Ok(())
}
