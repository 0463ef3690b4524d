//! The `inspc` command line: the only place that does IO (with `cli/`, its helpers).

mod cli;

use clap::{Parser, Subcommand, ValueEnum};
use inspc::diag::{render_human, to_json, RenderOptions};
use inspc::source::FsWorld;
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "inspc",
    version,
    about = "Compiles .insp inspection specs into CMM programs"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// How every command prints its diagnostics: graphical on stderr, or one JSON object
    /// per diagnostic per line on stdout (the command's summary lines then go to stderr).
    #[arg(long, global = true, value_enum, default_value_t = MessageFormat::Human)]
    message_format: MessageFormat,
}

/// The `--message-format` of this run, set once in `main` before any command runs.
static MESSAGE_FORMAT: std::sync::OnceLock<MessageFormat> = std::sync::OnceLock::new();

/// The `--message-format` of this run.
fn message_format() -> MessageFormat {
    MESSAGE_FORMAT
        .get()
        .copied()
        .unwrap_or(MessageFormat::Human)
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum MessageFormat {
    /// Graphical reports on stderr.
    Human,
    /// One JSON object per diagnostic per line on stdout.
    Json,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Emit {
    /// Only diagnostics.
    Nothing,
    /// The resolved model as text on stdout.
    Model,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum TableFormat {
    /// A table for people.
    Text,
    /// One JSON array.
    Json,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum BackendArg {
    /// The GPU when wgpu finds a hardware adapter, else the CPU (the command says which).
    Auto,
    /// The software rasterizer: the reference, the same bytes on every machine.
    Cpu,
    /// wgpu on any adapter (Vulkan: a GPU, or Mesa's lavapipe); an error without one.
    Gpu,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum GraphFormat {
    /// Graphviz DOT.
    Dot,
    /// A Mermaid flowchart.
    Mermaid,
    /// JSON with every fpoint's position and normal.
    Json,
}

#[derive(Subcommand)]
enum Command {
    /// Checks specs: parses, resolves names and units, checks values. Exits 1 on error.
    Check {
        /// The `.insp` files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Stop after the front end: skip geometry and sampling.
        #[arg(long)]
        front_end_only: bool,
        /// What to print besides diagnostics.
        #[arg(long, value_enum, default_value_t = Emit::Nothing)]
        emit: Emit,
    },
    /// Builds a spec into a DMIS program: plans, paths, program. Writes nothing unless
    /// every plan succeeds.
    Build {
        /// The `.insp` spec.
        file: PathBuf,
        /// Where to write the program (default: the plan's `output { dmis }`, else
        /// `<spec>.dmi` beside the spec).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Also write the plan with its paths as JSON.
        #[arg(long)]
        plan_json: Option<PathBuf>,
        #[command(flatten)]
        search: Search,
        /// Write the program even when some tolerances cannot be measured (each is
        /// listed as a warning), instead of failing.
        #[arg(long)]
        allow_unmeasured: bool,
    },
    /// Plans every plan of a spec: setups, probes, orientations and what each inspects
    /// (the high-level inspection plan), as the program is built from it — after the
    /// path stage's re-plans.
    Plan {
        /// The `.insp` spec.
        file: PathBuf,
        /// Output format.
        #[arg(long, value_enum, default_value_t = TableFormat::Text)]
        format: TableFormat,
        #[command(flatten)]
        search: Search,
        /// First list the setups each plan may use: the poses the part stands in on the
        /// table, those excluded and why, and what its fixtures can hold.
        #[arg(long)]
        explain_setups: bool,
    },
    /// Runs a DMIS program on a virtual CMM against the part of its spec: moves swept
    /// with the real probe, touches searched on the actual surfaces, features fitted,
    /// alignments built, every tolerance it outputs judged. Exits 0 when every one is
    /// in tolerance, 2 when some are out, 1 when the run stops.
    Simulate {
        /// The `.dmi` program (as `inspc build` wrote it).
        program: PathBuf,
        /// The `.insp` spec it was built from.
        spec: PathBuf,
        /// How the part and its placement differ from nominal: a file (`--help` shows
        /// its format).
        #[arg(long, long_help = DEVIATIONS_FORMAT)]
        deviations: Option<PathBuf>,
        /// Measurement noise: standard deviation along each touch's vector (mm).
        #[arg(long, default_value_t = 0.0)]
        noise: f64,
        /// Seed of the noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Also write the report: `.json` as JSON, `.dmo` as DMIS output, `.qif` as QIF 3
        /// Results, else text.
        #[arg(long)]
        report: Option<PathBuf>,
    },
    /// Shows whether a program sees what it claims to measure: builds the spec (or
    /// takes `--program`) and runs it on the virtual CMM at nominal, at random placements
    /// of the part, with each tolerance's forbidden deviation at 2x and 0.5x its zone,
    /// and with each size at its limits. Exits 0 when every trial reads as it should, 2
    /// when some do not, 1 when nothing could run.
    Verify {
        /// The `.insp` spec.
        spec: PathBuf,
        /// A program to try instead of the one the spec builds.
        #[arg(long)]
        program: Option<PathBuf>,
        /// Random placements tried.
        #[arg(long, default_value_t = 20)]
        placements: usize,
        /// Largest shift of a placement in machine x and y (mm).
        #[arg(long, default_value_t = 5.0)]
        shift: f64,
        /// Largest turn of a placement about the vertical (degrees).
        #[arg(long, default_value_t = 3.0)]
        turn: f64,
        /// Also write the results as JSON to this file.
        #[arg(long)]
        json: Option<PathBuf>,
        #[command(flatten)]
        search: Search,
    },
    /// Builds a spec and draws the plan as one self-contained HTML page: the part in 3D
    /// with faces coloured by feature, each setup's pose on the table with its fixture,
    /// points, paths, the probe at a touch and that touch's accessibility cone.
    View {
        /// The `.insp` spec.
        file: PathBuf,
        /// Where to write the page (default: `<spec>.html` beside the spec).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Also write a still image of each setup into this folder (`<spec>_setup<k>.png`).
        #[arg(long, value_name = "DIR")]
        png: Option<PathBuf>,
        #[command(flatten)]
        search: Search,
    },
    /// Formats specs in place in the one canonical layout (indentation, spacing, blank
    /// lines; comments and line breaks kept). A file that does not parse is left alone.
    Fmt {
        /// The `.insp` files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Write nothing; exit 1 and name the files that are not formatted.
        #[arg(long)]
        check: bool,
    },
    /// Writes a starter spec from a STEP or QIF file: the part read from its B-rep, a feature per
    /// PMI feature, every datum, tolerance and size the language can express (a comment
    /// for each it cannot), a CMM and probes sized to the part, and a plan.
    Import {
        /// The `.stp`, `.step` or `.qif` file.
        file: PathBuf,
        /// Where to write the spec (default: standard output).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Scale the file's geometry by this factor after its own unit (10 reads a
        /// 10 mm model as a 100 mm part); the spec's `mesh` says it again.
        #[arg(long, default_value_t = 1.0, value_parser = scale_arg)]
        scale: f64,
    },
    /// Reads a DMIS program and checks it as a controller would: line lengths, labels,
    /// names defined before use, MEAS blocks.
    Dmis {
        /// The `.dmi` file.
        file: PathBuf,
    },
    /// Lists the faces of a mesh (STL, OBJ) or of every part of a spec: id, surface type,
    /// area, centroid, normal or axis and radius.
    Faces {
        /// A mesh file or an `.insp` spec.
        file: PathBuf,
        /// Segment the mesh even when it has groups.
        #[arg(long)]
        segment: bool,
        /// The unit the mesh file is in.
        #[arg(long, default_value = "mm")]
        units: String,
        /// Output format.
        #[arg(long, value_enum, default_value_t = TableFormat::Text)]
        format: TableFormat,
    },
    /// Prints the measurement graph (part → tolerance → feature → face → fpoint) of every
    /// plan in the spec, or of its parts when it has no plan.
    Graph {
        /// The `.insp` spec.
        file: PathBuf,
        /// Output format.
        #[arg(long, value_enum, default_value_t = GraphFormat::Dot)]
        format: GraphFormat,
        /// Draw every fpoint as a node (DOT and Mermaid); otherwise faces show counts.
        #[arg(long)]
        points: bool,
    },
    /// Computes the accessibility cones of one fpoint under one probe: prints how much of
    /// the sphere each probe component leaves free and draws the probe's cone as an
    /// unfolded cube map (binary PGM).
    Cones {
        /// The `.insp` spec.
        file: PathBuf,
        /// A face, by the name `inspc faces` gives it; all fpoints when absent.
        #[arg(long)]
        face: Option<String>,
        /// Which fpoint of the face (or of the part), from 0.
        #[arg(long, default_value_t = 0)]
        point: usize,
        /// A probe label of the plan's machine; its first probe when absent.
        #[arg(long)]
        probe: Option<String>,
        /// Cube-map resolution (pixels per cube-face side).
        #[arg(short = 'n', long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(2..=256))]
        resolution: u32,
        /// Where to write the image.
        #[arg(short, long, default_value = "cone.pgm")]
        output: PathBuf,
    },
    /// The language server, over standard input and output: diagnostics as you type,
    /// hover, go to definition, references, symbols, completion, rename, formatting.
    Lsp {
        /// Plan FILE and print the result for the server (what the server runs on save,
        /// in a child process it can stop); ends (code 3) when standard input ends, the
        /// server's pipe, so it never outlives the server.
        #[arg(long, hide = true)]
        plan: Option<PathBuf>,
    },
}

/// The deviations file's format, for `simulate --help` (`simulate/deviation.rs` reads it).
const DEVIATIONS_FORMAT: &str = "\
How the part and its placement differ from nominal: a file of one change per line, \
`#` to the end of a line a comment, lengths in mm and angles in degrees (a trailing \
`mm` or `deg` may say so):

  feature NAME move (x, y, z)            its faces translate (part frame)
  feature NAME tilt DEG about (x, y, z)  turn about an axis through its centroid
  feature NAME grow MM                   its size grows: a diameter, a slot's width
  face NAME shift MM                     a plane moves along its outward normal
  face NAME bow MM                       a plane's centre stands out (flatness)
  part move (x, y)                       the part lies off on the table (machine x, y)
  part turn DEG                          ... and turned about the vertical
  setup N move (x, y) | setup N turn DEG the same, in setup N only

A feature is named as in the spec; a face as `inspc faces SPEC` lists it (stock.top, \
face_12) or by the name of a feature whose faces it changes. Changes to one face \
compose in file order.";

/// How hard the planner searches.
#[derive(clap::Args)]
struct Search {
    /// Cube-map resolution of the accessibility cones.
    #[arg(short = 'n', long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(8..=256))]
    resolution: u32,
    /// Generate-and-test rounds (in the search that validates each touch with the part
    /// turned, those before the first that validates do not count, up to as many
    /// again); when none settles, the plan is the best one found less the touches that
    /// never validated, each face's left-out points named.
    #[arg(long, default_value_t = 40, value_parser = clap::value_parser!(u32).range(1..=1000))]
    rounds: u32,
    /// Which backend computes the accessibility cones. The GPU's cones err on the blocked
    /// side by f32 rounding, so its plans can differ from the CPU's; `cpu` gives the
    /// same bytes on every machine.
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    backend: BackendArg,
}

impl Search {
    /// The planner's options; None, after saying why, when `--backend gpu` finds no
    /// adapter.
    fn options(&self, allow_unmeasured: bool) -> Option<inspc::plan::PlanOptions> {
        use inspc::access::BackendKind;
        if self.backend != BackendArg::Cpu && std::env::var_os("XDG_RUNTIME_DIR").is_none() {
            // Mesa's Vulkan loader prints "error: XDG_RUNTIME_DIR is invalid" once per
            // device query without it, which reads as inspc's error. Nothing has started a
            // thread yet (planning starts after the options are read).
            std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir());
        }
        let backend = match self.backend {
            BackendArg::Cpu => BackendKind::Cpu,
            BackendArg::Auto => {
                let (kind, why) = inspc::access::auto_backend();
                eprintln!("inspc: {why}");
                kind
            }
            BackendArg::Gpu => match inspc::access::gpu() {
                Ok(g) => {
                    eprintln!("inspc: cones on the GPU: {}", g.adapter());
                    BackendKind::Gpu
                }
                Err(why) => {
                    eprintln!(
                        "inspc: --backend gpu: wgpu found no adapter ({why}); install a Vulkan driver (Debian: mesa-vulkan-drivers) or use --backend cpu"
                    );
                    return None;
                }
            },
        };
        Some(inspc::plan::PlanOptions {
            n: self.resolution,
            max_iterations: self.rounds as usize,
            allow_unmeasured,
            backend,
            ..Default::default()
        })
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let _ = MESSAGE_FORMAT.set(cli.message_format);
    match cli.command {
        Command::Faces {
            file,
            segment,
            units,
            format,
        } => faces(&file, segment, &units, format),
        Command::Graph {
            file,
            format,
            points,
        } => graph(&file, format, points),
        Command::Cones {
            file,
            face,
            point,
            probe,
            resolution,
            output,
        } => {
            let req = inspc::access::ConeRequest {
                face,
                point,
                probe,
                n: resolution,
            };
            cones(&file, &req, &output)
        }
        Command::Plan {
            file,
            format,
            search,
            explain_setups,
        } => match search.options(false) {
            Some(opts) => plan(&file, format, &opts, explain_setups),
            None => ExitCode::from(2),
        },
        Command::Build {
            file,
            output,
            plan_json,
            search,
            allow_unmeasured,
        } => match search.options(allow_unmeasured) {
            Some(opts) => build(&file, output, plan_json, &opts),
            None => ExitCode::from(2),
        },
        Command::Dmis { file } => read_dmis(&file),
        Command::Fmt { files, check } => fmt(&files, check),
        Command::View {
            file,
            output,
            png,
            search,
        } => match search.options(false) {
            Some(opts) => view(&file, output, png, &opts),
            None => ExitCode::from(2),
        },
        Command::Lsp { plan } => lsp(plan.as_deref()),
        Command::Import {
            file,
            output,
            scale,
        } => import(&file, output, scale),
        Command::Simulate {
            program,
            spec,
            deviations,
            noise,
            seed,
            report,
        } => simulate(&program, &spec, deviations.as_deref(), noise, seed, report),
        Command::Verify {
            spec,
            program,
            placements,
            shift,
            turn,
            json,
            search,
        } => {
            let Some(plan_opts) = search.options(false) else {
                return ExitCode::from(1);
            };
            let opts = inspc::verify::Options {
                placements,
                shift,
                turn,
            };
            verify(&spec, program.as_deref(), &plan_opts, &opts, json)
        }
        Command::Check {
            files,
            emit,
            front_end_only,
        } => check(&files, emit, front_end_only),
    }
}

/// `inspc lsp`: the language server on standard input and output, or with `--plan`, one
/// file planned for it.
fn lsp(plan: Option<&std::path::Path>) -> ExitCode {
    if let Some(file) = plan {
        println!("{}", inspc::lsp::plan_file(file));
        return ExitCode::SUCCESS;
    }
    match inspc::lsp::stdio() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("inspc lsp: {e}");
            ExitCode::from(1)
        }
    }
}

/// `inspc check`: every file's diagnostics (as text on stderr or JSON on stdout), the
/// model when asked and nothing failed, and a count of errors and warnings.
fn check(files: &[PathBuf], emit: Emit, front_end_only: bool) -> ExitCode {
    let message_format = message_format();
    let checked = if front_end_only {
        inspc::check(&FsWorld, files)
    } else {
        inspc::measurement_graphs(&FsWorld, files).0
    };
    let mut stdout = std::io::stdout().lock();
    let mut stderr = std::io::stderr().lock();
    let opts = RenderOptions {
        width: 100,
        color: std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none(),
    };
    for d in &checked.diagnostics {
        match message_format {
            MessageFormat::Json => {
                let _ = writeln!(stdout, "{}", to_json(&checked.sources, d));
            }
            MessageFormat::Human => {
                let _ = write!(stderr, "{}", render_human(&checked.sources, d, opts));
            }
        }
    }
    if emit == Emit::Model && !checked.has_errors() {
        let _ = write!(stdout, "{}", checked.summary());
    }
    let errors = checked
        .diagnostics
        .iter()
        .filter(|d| d.severity() == miette::Severity::Error)
        .count();
    let warnings = checked.diagnostics.len() - errors;
    if message_format == MessageFormat::Human {
        let plural = |n: usize, w: &str| format!("{n} {w}{}", if n == 1 { "" } else { "s" });
        let _ = if errors > 0 {
            writeln!(
                stderr,
                "inspc: {} and {} in {}",
                plural(errors, "error"),
                plural(warnings, "warning"),
                plural(files.len(), "file")
            )
        } else {
            writeln!(
                stderr,
                "inspc: {} checked, no errors ({})",
                plural(files.len(), "file"),
                plural(warnings, "warning")
            )
        };
    }
    if errors > 0 {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

/// Prints diagnostics in the run's `--message-format`.
fn print_diagnostics(sources: &inspc::source::SourceMap, diags: &[inspc::diag::Diagnostic]) {
    let opts = RenderOptions {
        width: 100,
        color: std::io::stderr().is_terminal() && std::env::var_os("NO_COLOR").is_none(),
    };
    for d in diags {
        match message_format() {
            MessageFormat::Human => eprint!("{}", render_human(sources, d, opts)),
            MessageFormat::Json => println!("{}", to_json(sources, d)),
        }
    }
}

/// Prints a command's summary line: on stdout, or on stderr where stdout carries JSON
/// diagnostics.
macro_rules! say {
    ($($arg:tt)*) => {
        match message_format() {
            MessageFormat::Human => println!($($arg)*),
            MessageFormat::Json => eprintln!($($arg)*),
        }
    };
}

fn cones(
    file: &std::path::Path,
    req: &inspc::access::ConeRequest,
    output: &std::path::Path,
) -> ExitCode {
    let (checked, parts, graphs) = inspc::measurement_graphs(&FsWorld, &[file.to_path_buf()]);
    print_diagnostics(&checked.sources, &checked.diagnostics);
    if checked.has_errors() {
        return ExitCode::from(1);
    }
    let mut diags = inspc::diag::Diagnostics::new();
    let report = graphs.first().and_then(|gr| {
        let model = &checked.model;
        let input = inspc::access::ConeInput {
            model,
            part: &model.parts[gr.part],
            geometry: &parts[gr.part].as_ref()?.geometry,
            fpoints: &gr.graph.fpoints,
            plan: gr
                .graph
                .plan
                .as_ref()
                .and_then(|name| model.plans.iter().find(|p| &p.name == name)),
        };
        inspc::access::cone_report(&input, req, &mut diags)
    });
    print_diagnostics(&checked.sources, &diags.sorted());
    let Some(report) = report else {
        return ExitCode::from(1);
    };
    let image = cli::outputs::Output {
        path: output.to_path_buf(),
        bytes: report.pgm,
        what: "the cone image",
    };
    if let Err(code) = commit(&[image], &checked.inputs()) {
        return code;
    }
    print!("{}", report.text);
    println!(
        "wrote {} (unfolded cube, +z in the middle: free white, blocked black)",
        output.display()
    );
    ExitCode::SUCCESS
}

fn plan(
    file: &std::path::Path,
    format: TableFormat,
    opts: &inspc::plan::PlanOptions,
    explain: bool,
) -> ExitCode {
    let start = std::time::Instant::now();
    // The plan `build` writes: a configuration the path stage cannot route is planned
    // again there, so the plan before the paths can differ from the program's.
    let run = whole_run(file, opts);
    let (checked, parts) = (&run.checked, &run.parts);
    if explain {
        let model = &checked.model;
        for plan in &model.plans {
            if let Some(Some(data)) = parts.get(plan.part.0) {
                print!(
                    "{}",
                    inspc::plan::explain_setups(model, plan, &data.geometry, &data.fixtures)
                );
            }
        }
    }
    print_diagnostics(&checked.sources, &checked.diagnostics);
    if checked.has_errors() {
        return ExitCode::from(1);
    }
    let hlips: Vec<(&inspc::plan::Hlip, inspc::plan::Names)> = run
        .built
        .iter()
        .filter_map(|b| Some((&b.hlip, inspc::plan_names(checked, parts, b.plan)?)))
        .collect();
    match format {
        TableFormat::Text => {
            for (h, names) in &hlips {
                print!("{}", inspc::plan::text(h, names));
            }
            eprintln!("inspc: planned in {:.2} s", start.elapsed().as_secs_f64());
        }
        TableFormat::Json => {
            let all: Vec<serde_json::Value> = hlips
                .iter()
                .map(|(h, names)| inspc::plan::json(h, names))
                .collect();
            let v = if all.len() == 1 {
                all.into_iter().next().unwrap_or_default()
            } else {
                serde_json::Value::Array(all)
            };
            println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
        }
    }
    ExitCode::SUCCESS
}

/// `inspc build`: the whole pipeline, then every output written atomically.
fn build(
    file: &std::path::Path,
    output: Option<PathBuf>,
    plan_json: Option<PathBuf>,
    opts: &inspc::plan::PlanOptions,
) -> ExitCode {
    let start = std::time::Instant::now();
    let bar = indicatif::ProgressBar::new_spinner();
    if std::io::stderr().is_terminal() {
        bar.enable_steady_tick(std::time::Duration::from_millis(120));
    } else {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let report = |what: &str, done: usize, total: usize| {
        if total > 1 {
            bar.set_message(format!("{what} {done}/{total}"));
        } else {
            bar.set_message(what.to_string());
        }
    };
    let (checked, built, timings) = inspc::build(&FsWorld, &[file.to_path_buf()], opts, &report);
    bar.finish_and_clear();
    let named = (output.is_some() || plan_json.is_some())
        .then_some("-o and --plan-json name one file, so leave them out");
    if let Err(code) = writable(file, &checked, built.len(), "build", named) {
        return code;
    }
    // Every file is decided before any is written.
    let (dir, stem) = beside(file);
    let mut writes: Vec<cli::outputs::Output> = Vec::new();
    let mut push = |path: PathBuf, bytes: Vec<u8>, what: &'static str| {
        writes.push(cli::outputs::Output { path, bytes, what });
    };
    for b in &built {
        let plan = &checked.model.plans[b.plan];
        let dmi = output.clone().unwrap_or_else(|| match &plan.outputs.dmis {
            Some(p) => dir.join(p),
            None if built.len() == 1 => dir.join(format!("{stem}.dmi")),
            None => dir.join(format!("{stem}_{}.dmi", plan.name)),
        });
        push(dmi, b.dmis.clone().into_bytes(), "the program");
        let json = plan_json
            .clone()
            .or_else(|| plan.outputs.plan.as_ref().map(|p| dir.join(p)));
        if let Some(j) = json {
            let text = serde_json::to_string_pretty(&b.json).unwrap_or_default() + "\n";
            push(j, text.into_bytes(), "the plan JSON");
        }
        if let (Some(g), Some(text)) = (&plan.outputs.graph, &b.graph) {
            push(dir.join(g), text.clone().into_bytes(), "the graph");
        }
    }
    if let Err(code) = commit(&writes, &checked.inputs()) {
        return code;
    }
    for b in &built {
        let h = &b.hlip;
        let l = &b.llip;
        let s = &h.summary;
        let n = |k: usize, w: &str| {
            let es = if w.ends_with("ch") { "es" } else { "s" };
            format!("{k} {w}{}", if k == 1 { "" } else { es })
        };
        say!(
            "plan {}: tolerances measured {} of {}, {}, {}, {}, {}, {}",
            checked.model.plans[b.plan].name,
            s.tolerances.0,
            s.tolerances.1,
            n(s.setups, "setup"),
            n(s.probes_used, "probe"),
            n(s.orientations, "orientation"),
            n(s.features, "feature"),
            n(l.summary.touches, "touch")
        );
        say!(
            "  path {:.2} m in {} ({} roadmap nodes added, {} moves checked)",
            l.summary.length / 1000.0,
            n(l.summary.groups, "group"),
            l.summary.added_nodes,
            l.summary.checks
        );
        let m = l.motion.margin;
        let fmt = inspc::model::fmt_num;
        if l.summary.tight.is_empty() {
            say!("  moves keep {} mm from part, fixtures and table", fmt(m));
        } else {
            let faces: Vec<String> = b
                .tight
                .iter()
                .take(6)
                .map(|(face, x)| format!("{face} {} mm", fmt(*x)))
                .collect();
            let more = b.tight.len().saturating_sub(6);
            say!(
                "  moves keep {} mm from part, fixtures and table; less at stand-offs on {}{}",
                fmt(m),
                faces.join(", "),
                if more > 0 {
                    format!(" and {more} more faces")
                } else {
                    String::new()
                }
            );
        }
    }
    let stages: Vec<String> = timings
        .stages
        .iter()
        .map(|(s, t)| format!("{s} {t:.2} s"))
        .collect();
    say!("  time: {}", stages.join(", "));
    for w in &writes {
        say!("wrote {} ({} bytes)", w.path.display(), w.bytes.len());
    }
    eprintln!("inspc: built in {:.2} s", start.elapsed().as_secs_f64());
    ExitCode::SUCCESS
}

/// `inspc dmis`: reads a program and reports what a controller would reject.
/// After a run that writes a file per plan: its diagnostics printed, and the exit code
/// when nothing may be written — an error, no plan to `verb`, or one output file
/// `named` on the command line for several plans.
fn writable(
    file: &std::path::Path,
    checked: &inspc::Checked,
    plans: usize,
    verb: &str,
    named: Option<&str>,
) -> Result<(), ExitCode> {
    print_diagnostics(&checked.sources, &checked.diagnostics);
    if checked.has_errors() {
        eprintln!("inspc: nothing written");
        return Err(ExitCode::from(1));
    }
    if plans == 0 {
        eprintln!("inspc: {} has no plan to {verb}", file.display());
        return Err(ExitCode::from(1));
    }
    if let Some(named) = named.filter(|_| plans > 1) {
        eprintln!(
            "inspc: {} holds {plans} plans; {named} and each plan writes its own",
            file.display()
        );
        return Err(ExitCode::from(2));
    }
    Ok(())
}

/// Where a spec's outputs go by default: its folder, and its file stem.
fn beside(file: &std::path::Path) -> (&std::path::Path, String) {
    let dir = file.parent().unwrap_or(std::path::Path::new(""));
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "spec".into());
    (dir, stem)
}

/// The whole pipeline on one spec, every stage's result kept, without a progress bar.
fn whole_run(file: &std::path::Path, opts: &inspc::plan::PlanOptions) -> inspc::Run {
    let roots = [file.to_path_buf()];
    inspc::run(&FsWorld, &roots, opts, inspc::Until::Build, &|_, _, _| {})
}

/// `inspc view`: the pipeline, then the page (and images) of every plan, written
/// atomically.
fn view(
    file: &std::path::Path,
    output: Option<PathBuf>,
    png: Option<PathBuf>,
    opts: &inspc::plan::PlanOptions,
) -> ExitCode {
    let run = whole_run(file, opts);
    let checked = &run.checked;
    let named = output
        .is_some()
        .then_some("-o names one file, so leave it out");
    if let Err(code) = writable(file, checked, run.built.len(), "view", named) {
        return code;
    }
    let (dir, stem) = beside(file);
    let mut writes: Vec<cli::outputs::Output> = Vec::new();
    for b in &run.built {
        let model = &checked.model;
        let plan = &model.plans[b.plan];
        let Some(Some(data)) = run.parts.get(plan.part.0) else {
            continue;
        };
        let scene = inspc::view::scene(model, data, b);
        let name = if run.built.len() == 1 {
            stem.clone()
        } else {
            format!("{stem}_{}", plan.name)
        };
        let html = output
            .clone()
            .unwrap_or_else(|| dir.join(format!("{name}.html")));
        writes.push(cli::outputs::Output {
            path: html,
            bytes: inspc::view::page(&scene).into_bytes(),
            what: "the plan's page",
        });
        if let Some(png_dir) = &png {
            for k in 0..scene.setups.len() {
                if let Some(bytes) = inspc::view::png(&scene, k, 960, 720) {
                    writes.push(cli::outputs::Output {
                        path: png_dir.join(format!("{name}_setup{}.png", k + 1)),
                        bytes,
                        what: "a setup's image",
                    });
                }
            }
        }
    }
    // The images' folder is made only when an image goes into it, and a path that
    // cannot be one is a diagnostic like any output's.
    if let Some(d) = png
        .as_ref()
        .filter(|d| writes.iter().any(|w| w.path.starts_with(d)))
    {
        let mut sources = inspc::source::SourceMap::new();
        if let Err(e) = cli::outputs::folder(d, &mut sources) {
            let mut diags = inspc::diag::Diagnostics::new();
            diags.push(e);
            print_diagnostics(&sources, &diags.sorted());
            return ExitCode::from(1);
        }
    }
    if let Err(code) = commit(&writes, &checked.inputs()) {
        return code;
    }
    for w in &writes {
        println!("wrote {} ({} bytes)", w.path.display(), w.bytes.len());
    }
    ExitCode::SUCCESS
}

fn simulate(
    program: &std::path::Path,
    spec: &std::path::Path,
    deviations: Option<&std::path::Path>,
    noise: f64,
    seed: u64,
    report: Option<PathBuf>,
) -> ExitCode {
    if !(noise.is_finite() && noise >= 0.0) {
        eprintln!("inspc: --noise takes a standard deviation in mm, 0 or more");
        return ExitCode::from(2);
    }
    let opts = inspc::simulate::Options { noise, seed };
    let run = inspc::simulate(&FsWorld, spec, program, deviations, &opts);
    print_diagnostics(&run.checked.sources, &run.checked.diagnostics);
    let Some(r) = run.report else {
        eprintln!("inspc: the run stopped");
        return ExitCode::from(1);
    };
    if let Some(path) = report {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        let bytes = match ext {
            "json" => serde_json::to_string_pretty(&r.json()).unwrap_or_default() + "\n",
            "dmo" => r.dmis(),
            "qif" => {
                let text = run
                    .checked
                    .sources
                    .find_path(program)
                    .map(|id| run.checked.sources.get(id).text.as_str())
                    .unwrap_or_default();
                let meta = inspc::simulate::QifMeta::new(spec, program, text);
                inspc::simulate::qif_results(&r, &meta)
            }
            _ => r.text(),
        };
        let out = cli::outputs::Output {
            path,
            bytes: bytes.into_bytes(),
            what: "the report",
        };
        if let Err(code) = commit(&[out], &run.checked.inputs()) {
            return code;
        }
    }
    print!("{}", r.text());
    if r.failed() > 0 {
        ExitCode::from(2)
    } else {
        ExitCode::SUCCESS
    }
}

/// `inspc verify`: the battery's report per program; exit 2 when it found problems.
fn verify(
    spec: &std::path::Path,
    program: Option<&std::path::Path>,
    plan_opts: &inspc::plan::PlanOptions,
    opts: &inspc::verify::Options,
    json: Option<PathBuf>,
) -> ExitCode {
    if !(opts.shift.is_finite() && opts.shift >= 0.0 && opts.turn.is_finite() && opts.turn >= 0.0) {
        eprintln!("inspc: --shift and --turn take a distance and an angle, 0 or more");
        return ExitCode::from(2);
    }
    let run = inspc::verify(&FsWorld, spec, program, plan_opts, opts);
    print_diagnostics(&run.checked.sources, &run.checked.diagnostics);
    if run.results.is_empty() {
        eprintln!("inspc: no program to verify");
        return ExitCode::from(1);
    }
    if let Some(path) = json {
        let v: Vec<serde_json::Value> = run.results.iter().map(|r| r.json()).collect();
        let text = serde_json::to_string_pretty(&v).unwrap_or_default() + "\n";
        let out = cli::outputs::Output {
            path,
            bytes: text.into_bytes(),
            what: "the results",
        };
        if let Err(code) = commit(&[out], &run.checked.inputs()) {
            return code;
        }
    }
    for r in &run.results {
        print!("{}", r.text());
    }
    if run.results.iter().any(|r| r.problems() > 0) {
        ExitCode::from(2)
    } else {
        ExitCode::SUCCESS
    }
}

/// Reads a file the command line names into `sources`; an unreadable one is a diagnostic
/// in `diags`, filed under its path.
fn read_source(
    sources: &mut inspc::source::SourceMap,
    diags: &mut inspc::diag::Diagnostics,
    file: &std::path::Path,
    kind: inspc::source::FileKind,
) -> Option<inspc::source::FileId> {
    use inspc::source::World;
    let shown = file.display().to_string();
    match FsWorld.read(file, kind) {
        Ok(b) => {
            let text = String::from_utf8_lossy(&b).into_owned();
            Some(sources.add(shown, Some(file.to_path_buf()), text))
        }
        Err(e) => {
            let id = sources.add(shown.clone(), Some(file.to_path_buf()), String::new());
            diags.push(inspc::source::io::IoError::Unreadable {
                file: id,
                path: shown,
                reason: e.0,
            });
            None
        }
    }
}

/// `inspc fmt`: formats every file that parses; with `--check`, only says which are not
/// formatted. A file that does not parse (or cannot be read) is named, left as it is,
/// and fails the run.
fn fmt(files: &[PathBuf], check: bool) -> ExitCode {
    let mut sources = inspc::source::SourceMap::new();
    let mut diags = inspc::diag::Diagnostics::new();
    let mut writes: Vec<cli::outputs::Output> = Vec::new();
    let mut parsed = 0;
    for file in files {
        let Some(id) = read_source(
            &mut sources,
            &mut diags,
            file,
            inspc::source::FileKind::Spec,
        ) else {
            continue;
        };
        let text = &sources.get(id).text;
        if let Err(e) = inspc::syntax::parse(id, text) {
            diags.push(e);
            continue;
        }
        parsed += 1;
        // It parses, so `None` means the layout would change what the spec says.
        let Some(formatted) = inspc::fmt::format_checked(text) else {
            eprintln!(
                "inspc: internal error: formatting {} would change its meaning; it is left as it is (please report)",
                file.display()
            );
            return ExitCode::from(101);
        };
        if formatted == *text {
            continue;
        }
        writes.push(cli::outputs::Output {
            path: file.clone(),
            bytes: formatted.into_bytes(),
            what: "the formatted spec",
        });
    }
    // Like rustfmt and gofmt: every file that parses is formatted, each one that does not
    // is named and left as it is, and the run fails.
    let failed = diags.has_errors();
    print_diagnostics(&sources, &diags.sorted());
    let unparsed = files.len() - parsed;
    if check {
        for w in &writes {
            let f = w.path.display();
            say!("{f}: not formatted (run `inspc fmt {f}`)");
        }
    } else {
        if let Err(code) = commit(&writes, &[]) {
            return code;
        }
        for w in &writes {
            say!("formatted {}", w.path.display());
        }
    }
    let plural = |n: usize| if n == 1 { "file" } else { "files" };
    let already = parsed - writes.len();
    let mut tally = vec![];
    if !writes.is_empty() {
        let done = if check { "to format" } else { "formatted" };
        tally.push(format!("{} {} {done}", writes.len(), plural(writes.len())));
    }
    if already > 0 {
        tally.push(format!("{already} {} already formatted", plural(already)));
    }
    if unparsed > 0 {
        tally.push(format!(
            "{unparsed} {} with errors left as {}",
            plural(unparsed),
            if unparsed == 1 { "it was" } else { "they were" }
        ));
    }
    eprintln!("inspc: {}", tally.join(", "));
    if failed || (check && !writes.is_empty()) {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    }
}

fn read_dmis(file: &std::path::Path) -> ExitCode {
    let mut sources = inspc::source::SourceMap::new();
    let mut diags = inspc::diag::Diagnostics::new();
    let Some(id) = read_source(
        &mut sources,
        &mut diags,
        file,
        inspc::source::FileKind::Dmis,
    ) else {
        print_diagnostics(&sources, &diags.sorted());
        return ExitCode::from(1);
    };
    match inspc::dmis::read(id, &sources.get(id).text) {
        Ok(mut p) => {
            let mut warnings = inspc::diag::Diagnostics::new();
            for w in std::mem::take(&mut p.warnings) {
                warnings.push(w);
            }
            print_diagnostics(&sources, &warnings.sorted());
            let count = |m: &str| p.commands(m).count();
            say!(
                "{}: {} statements, {} sensors, {} features, {} tolerances, {} MEAS blocks, {} touches, {} moves",
                file.display(),
                p.statements.len(),
                count("SNSDEF"),
                count("FEAT"),
                count("TOL"),
                count("MEAS"),
                count("PTMEAS"),
                count("GOTO")
            );
            ExitCode::SUCCESS
        }
        Err(errors) => {
            // A broken file can hold a problem on every line: show the first ones.
            const SHOWN: usize = 50;
            let n = errors.len();
            let mut diags = inspc::diag::Diagnostics::new();
            for e in errors.into_iter().take(SHOWN) {
                diags.push(e);
            }
            print_diagnostics(&sources, &diags.sorted());
            if n > SHOWN {
                eprintln!(
                    "inspc: {n} problems in {}, the first {SHOWN} shown",
                    file.display()
                );
            } else {
                eprintln!("inspc: {n} problems in {}", file.display());
            }
            ExitCode::from(1)
        }
    }
}

/// Writes every output or none (see `cli::outputs`); on failure the diagnostic is
/// printed and the exit code returned.
fn commit(outputs: &[cli::outputs::Output], inputs: &[PathBuf]) -> Result<(), ExitCode> {
    let mut sources = inspc::source::SourceMap::new();
    match cli::outputs::commit(outputs, inputs, &mut sources) {
        Ok(()) => Ok(()),
        Err(e) => {
            let mut diags = inspc::diag::Diagnostics::new();
            diags.push(e);
            print_diagnostics(&sources, &diags.sorted());
            Err(ExitCode::from(1))
        }
    }
}

fn graph(file: &std::path::Path, format: GraphFormat, points: bool) -> ExitCode {
    let (checked, parts, graphs) = inspc::measurement_graphs(&FsWorld, &[file.to_path_buf()]);
    print_diagnostics(&checked.sources, &checked.diagnostics);
    if checked.has_errors() {
        return ExitCode::from(1);
    }
    let mut out = String::new();
    let mut json = Vec::new();
    for (k, g) in graphs.iter().enumerate() {
        let part = &checked.model.parts[g.part];
        let Some(data) = &parts[g.part] else { continue };
        match format {
            GraphFormat::Dot => out += &inspc::graph::dot(part, &data.geometry, &g.graph, points),
            GraphFormat::Mermaid => {
                if k > 0 {
                    out.push('\n');
                }
                out += &inspc::graph::mermaid(part, &data.geometry, &g.graph, points);
            }
            GraphFormat::Json => json.push(inspc::graph::json(part, &data.geometry, &g.graph)),
        }
    }
    if format == GraphFormat::Json {
        out = serde_json::to_string_pretty(&json).unwrap_or_default() + "\n";
    }
    let _ = std::io::stdout().lock().write_all(out.as_bytes());
    ExitCode::SUCCESS
}

/// Prints a mesh file's error, labelled on its path (the command line named it, no spec).
fn mesh_error(file: &std::path::Path, e: inspc::geometry::MeshError) {
    let mut sources = inspc::source::SourceMap::new();
    let shown = file.to_string_lossy().into_owned();
    let id = sources.add(shown.clone(), None, shown.clone());
    let span = inspc::source::Span::new(id, 0, shown.len());
    let mut diags = inspc::diag::Diagnostics::new();
    for d in e.at(span, file) {
        diags.push(d);
    }
    print_diagnostics(&sources, &diags.sorted());
}

/// Prints the items an import left out, labelled on the file's path as the command line
/// named it.
fn import_warnings(file: &std::path::Path, warnings: &[inspc::import::LeftOut]) {
    if warnings.is_empty() {
        return;
    }
    let mut sources = inspc::source::SourceMap::new();
    let shown = file.to_string_lossy().into_owned();
    let id = sources.add(shown.clone(), None, shown.clone());
    let span = inspc::source::Span::new(id, 0, shown.len());
    let mut diags = inspc::diag::Diagnostics::new();
    for w in warnings {
        diags.push(w.at(span));
    }
    print_diagnostics(&sources, &diags.sorted());
}

/// `--scale`: a factor from 0.001 to 1000, as a spec's `mesh "…" { scale … }` takes.
fn scale_arg(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(s) if (0.001..=1000.0).contains(&s) => Ok(s),
        Ok(_) => Err("a scale runs from 0.001 to 1000".into()),
        Err(_) => Err("a scale is a number: 10 reads a 10 mm model as a 100 mm part".into()),
    }
}

/// `inspc import`: a spec from a STEP or QIF file, on stdout or written atomically.
fn import(file: &std::path::Path, output: Option<PathBuf>, scale: f64) -> ExitCode {
    use inspc::source::{FileKind, World};
    let bytes = match FsWorld.read(file, FileKind::Mesh) {
        Ok(b) => b,
        Err(e) => {
            mesh_error(file, inspc::geometry::MeshError::Unreadable(e.0));
            return ExitCode::from(1);
        }
    };
    let spec_dir = output
        .as_deref()
        .and_then(std::path::Path::parent)
        .filter(|d| !d.as_os_str().is_empty())
        .map_or_else(|| PathBuf::from("."), std::path::Path::to_path_buf);
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let opts = inspc::import::ImportOptions {
        cad_path: cli::outputs::relative_to(file, &spec_dir),
        part_name: inspc::import::identifier(&stem),
        scale,
    };
    let inspc::import::Imported {
        text,
        faces,
        datums: (d, dw),
        tolerances: (t, tw),
        dimensions: (s, sw),
        warnings,
        defaults,
    } = match inspc::import::import(&bytes, &opts) {
        Ok(i) => i,
        Err(e) => {
            mesh_error(file, e);
            return ExitCode::from(1);
        }
    };
    import_warnings(file, &warnings);
    match &output {
        Some(path) => {
            let out = cli::outputs::Output {
                path: path.clone(),
                bytes: text.into_bytes(),
                what: "the spec",
            };
            if let Err(code) = commit(&[out], &[file.to_path_buf()]) {
                return code;
            }
        }
        None => print!("{text}"),
    }
    let to = output
        .as_ref()
        .map(|p| format!(" to {}", p.display()))
        .unwrap_or_default();
    if defaults > 0 {
        eprintln!(
            "inspc: {faces} faces; no PMI: a default inspection of {defaults} tolerances (general tolerances, not the drawing's) written{to}"
        );
    } else {
        eprintln!(
            "inspc: {faces} faces; datums {dw} of {d}, tolerances {tw} of {t}, sizes and locations {sw} of {s} written{to}"
        );
    }
    ExitCode::SUCCESS
}

fn faces(file: &std::path::Path, segment: bool, units: &str, format: TableFormat) -> ExitCode {
    use inspc::geometry;
    let is_spec = file.extension().is_some_and(|e| e == "insp");
    let mut listed: Vec<(String, geometry::PartGeometry)> = Vec::new();
    if is_spec {
        let checked = inspc::check(&FsWorld, &[file.to_path_buf()]);
        print_diagnostics(&checked.sources, &checked.diagnostics);
        if checked.has_errors() {
            return ExitCode::from(1);
        }
        let mut diags = inspc::diag::Diagnostics::new();
        for part in checked
            .model
            .parts
            .iter()
            .filter(|p| checked.roots.contains(&p.span.file))
        {
            if let Some(g) = geometry::build(part, &FsWorld, &mut diags) {
                listed.push((part.name.clone(), g));
            }
        }
        let failed = diags.has_errors();
        print_diagnostics(&checked.sources, &diags.sorted());
        if failed {
            return ExitCode::from(1);
        }
    } else {
        let Some(unit_mm) = inspc::resolve::length_unit_mm(units) else {
            eprintln!("inspc: unknown length unit `{units}` (mm, cm, m, um, in)");
            return ExitCode::from(2);
        };
        let raw = match geometry::read_mesh(&FsWorld, file, unit_mm) {
            Ok(raw) => raw,
            Err(e) => {
                mesh_error(file, e);
                return ExitCode::from(1);
            }
        };
        if raw.open_edges + raw.nonmanifold_edges > 0 {
            eprintln!(
                "inspc: warning: {} open and {} non-manifold edges",
                raw.open_edges, raw.nonmanifold_edges
            );
        }
        let g = if raw.groups.len() > 1 && !segment {
            geometry::segment::from_groups(&raw)
        } else {
            geometry::segment::segment(&raw)
        };
        listed.push((file.to_string_lossy().into_owned(), g));
    }
    let mut out = std::io::stdout().lock();
    match format {
        TableFormat::Json => {
            let v: Vec<serde_json::Value> = listed.iter().map(|(name, g)| serde_json::json!({ "part": name, "faces": geometry::faces_json(g) })).collect();
            let _ = writeln!(out, "{}", serde_json::Value::Array(v));
        }
        TableFormat::Text => {
            for (name, g) in &listed {
                let _ = write!(out, "{}", geometry::faces_table(name, g));
            }
        }
    }
    ExitCode::SUCCESS
}
