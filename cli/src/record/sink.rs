//! Where a recording goes (file, standard output, a viewer, a server of
//! its own for `--serve`) and opening the Rerun stream on it.

use std::io::IsTerminal;
use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, SocketAddr};
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::Duration;

use rerun::{RecordingStream, RecordingStreamBuilder};

use super::layout::Layout;
use super::APP_ID;
use crate::driver::interrupt_flag;
use crate::error::CliError;

/// Address `--connect` uses without a value: a viewer started with plain `rerun`.
pub const DEFAULT_CONNECT_URL: &str = "rerun+http://127.0.0.1:9876/proxy";

pub use rerun::MemoryLimit;

/// Port `--serve` listens on without `--port`: Rerun's own default.
pub const DEFAULT_SERVE_PORT: u16 = rerun::DEFAULT_SERVER_PORT;

/// Memory limit of the `--serve` server without `--server-memory-limit`:
/// the default of Rerun's own `--serve` flag.
pub const DEFAULT_SERVER_MEMORY_LIMIT: &str = "25%";

/// Parses a `--server-memory-limit` the way Rerun does: `16GB`, `500MiB`,
/// `50%` (of the machine's memory), `0` or `unlimited`.
pub fn parse_memory_limit(text: &str) -> Result<MemoryLimit, String> {
    MemoryLimit::parse(text)
}

/// A gRPC server that the recording hosts (`--serve`): viewers connect to
/// it, during the run or after it, and get everything logged so far.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Serve {
    /// Address to listen on (`--bind`, default `0.0.0.0`: every interface).
    pub bind: IpAddr,
    /// Port to listen on (`--port`, default 9876).
    pub port: u16,
    /// How much of the recording the server keeps for viewers that connect
    /// late (`--server-memory-limit`); beyond it the oldest frames go first,
    /// static data (geometry, legend, blueprint) is always kept.
    pub memory_limit: MemoryLimit,
    /// Also save the recording to this `.rrd` file (`--save FILE`).
    pub save: Option<PathBuf>,
}

impl Serve {
    /// The URL a viewer connects to: `rerun --connect URL`. A server on
    /// every interface is reached at `127.0.0.1` on this machine.
    pub fn url(&self) -> String {
        let host = match self.bind {
            IpAddr::V4(ip) if ip.is_unspecified() => IpAddr::V4(Ipv4Addr::LOCALHOST),
            IpAddr::V6(ip) if ip.is_unspecified() => IpAddr::V6(Ipv6Addr::LOCALHOST),
            ip => ip,
        };
        format!("rerun+http://{}/proxy", SocketAddr::new(host, self.port))
    }

    /// Rerun's server starts on a thread of its own and only logs a failed
    /// start; binding the address here first turns a port in use (e.g. by a
    /// viewer started with plain `rerun`, which listens on 9876) into an error.
    fn check_address(&self) -> Result<(), CliError> {
        let addr = SocketAddr::new(self.bind, self.port);
        std::net::TcpListener::bind(addr).map(drop).map_err(|e| {
            CliError::Viewer(format!(
                "cannot serve on {addr}: {e}; is a Rerun viewer or server already listening \
                 there? Pick another port with --port, or stream into that viewer with \
                 --connect {}",
                self.url()
            ))
        })
    }
}

/// Where a recording goes: Rerun's usual sinks.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Sink {
    /// An `.rrd` file (`-o FILE`, `--save FILE`).
    File(PathBuf),
    /// Standard output (`-o -`), to pipe into `rerun -`.
    Stdout,
    /// A viewer started for this recording (`--spawn`, needs `rerun` on PATH).
    Spawn,
    /// A running viewer or server at this gRPC URL (`--connect [ADDR]`).
    Connect(String),
    /// A gRPC server of its own, for viewers to connect to (`--serve`),
    /// optionally with a copy in a file (`--serve --save FILE`).
    Serve(Serve),
}

impl Sink {
    /// The sink of `-o NAME`: `-` is standard output, anything else must be
    /// a file name ending in `.rrd` (the only format the viewer opens).
    pub fn output(name: &Path) -> Result<Sink, CliError> {
        if name.as_os_str() == "-" {
            return Ok(Sink::Stdout);
        }
        if name.extension().is_some_and(|e| e == "rrd") {
            Ok(Sink::File(name.to_path_buf()))
        } else {
            Err(CliError::Usage(format!(
                "output `{}` does not end in .rrd: Rerun recordings are .rrd files \
                 (or `-o -` for standard output, to pipe into `rerun -`)",
                name.display()
            )))
        }
    }

    /// The sink of `--connect ADDR`: a full `rerun+http://.../proxy` URL, or
    /// just `HOST:PORT`.
    pub fn connect(addr: &str) -> Sink {
        if addr.contains("://") {
            Sink::Connect(addr.to_string())
        } else {
            Sink::Connect(format!("rerun+http://{addr}/proxy"))
        }
    }

    /// The sink of `--serve`, saving to `output` too when given (`--save
    /// FILE`; standard output is refused: the server is the live stream).
    pub fn serve(
        bind: IpAddr,
        port: u16,
        memory_limit: MemoryLimit,
        output: Option<&Path>,
    ) -> Result<Sink, CliError> {
        let save = match output.map(Sink::output).transpose()? {
            None => None,
            Some(Sink::File(path)) => Some(path),
            Some(_) => {
                return Err(CliError::Usage(
                    "--serve does not write to standard output (`-o -`): connect a viewer to \
                     the server instead, or save a copy with --save FILE"
                        .into(),
                ))
            }
        };
        Ok(Sink::Serve(Serve {
            bind,
            port,
            memory_limit,
            save,
        }))
    }

    /// Where the data went, for the closing message.
    pub fn describe(&self) -> String {
        match self {
            Sink::File(p) => p.display().to_string(),
            Sink::Stdout => "standard output".into(),
            Sink::Spawn => "a new Rerun viewer".into(),
            Sink::Connect(url) => format!("the viewer at {url}"),
            Sink::Serve(s) => match &s.save {
                None => format!("the server at {}", s.url()),
                Some(p) => format!("the server at {} and {}", s.url(), p.display()),
            },
        }
    }

    /// An error of this sink, with the innermost cause only (Rerun's errors
    /// repeat the path and wrap the OS error).
    pub(super) fn error(&self, e: impl std::error::Error) -> CliError {
        let cause = root_cause(&e);
        match self {
            Sink::File(p) => CliError::output(p, cause),
            Sink::Stdout => CliError::Viewer(format!("cannot write to standard output: {cause}")),
            Sink::Spawn => CliError::Viewer(format!("cannot start a Rerun viewer: {cause}")),
            Sink::Connect(url) => {
                CliError::Viewer(format!("cannot stream to the viewer at {url}: {cause}"))
            }
            Sink::Serve(s) => CliError::Viewer(format!("cannot serve at {}: {cause}", s.url())),
        }
    }
}

/// The innermost error of a chain, as text.
fn root_cause(e: &dyn std::error::Error) -> String {
    let mut e = e;
    while let Some(inner) = e.source() {
        e = inner;
    }
    e.to_string()
}

/// The gRPC server of a `--serve` recording, serving everything logged to
/// viewers that connect; it stops when this is dropped.
pub struct Server {
    pub(super) rec: RecordingStream,
    pub(super) url: String,
}

impl std::fmt::Debug for Server {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Server").field("url", &self.url).finish()
    }
}

impl Server {
    /// The URL viewers connect to (`rerun --connect URL`).
    pub fn url(&self) -> &str {
        &self.url
    }

    /// Keeps serving until Ctrl-C, SIGTERM or SIGHUP, then shuts the server
    /// down (viewers keep what they received).
    pub fn serve_until_interrupted(self) {
        let interrupt = interrupt_flag();
        while !interrupt.load(Ordering::SeqCst) {
            std::thread::sleep(Duration::from_millis(100));
        }
        drop(self.rec);
    }
}

/// Opens the recording stream on its sink, without the wall-clock
/// `log_time` timeline.
pub(super) fn open(name: &str, layout: &Layout, sink: &Sink) -> Result<RecordingStream, CliError> {
    let builder = RecordingStreamBuilder::new(APP_ID).recording_name(name.to_string());
    let rec = match sink {
        Sink::File(path) => {
            // Rerun's own error repeats the path and nests the OS error.
            std::fs::File::create(path).map_err(|e| CliError::output(path, e))?;
            builder.save(path)
        }
        Sink::Stdout => {
            if std::io::stdout().is_terminal() {
                return Err(CliError::Usage(
                    "`-o -` writes the recording to standard output, which is a terminal here; \
                     pipe it into the viewer (`yarnsim record -o - | rerun -`) or give a file name"
                        .into(),
                ));
            }
            builder.stdout()
        }
        Sink::Spawn => builder.spawn(),
        Sink::Connect(url) => builder.connect_grpc_opts(url.clone()),
        Sink::Serve(s) => {
            s.check_address()?;
            let options = rerun::ServerOptions {
                memory_limit: s.memory_limit,
                ..Default::default()
            };
            match &s.save {
                None => builder.serve_grpc_opts(s.bind.to_string(), s.port, options),
                Some(path) => {
                    std::fs::File::create(path).map_err(|e| CliError::output(path, e))?;
                    let file = rerun::sink::FileSink::new(path)
                        .map_err(|e| CliError::output(path, root_cause(&e)))?;
                    let server = rerun::grpc_server::GrpcServerSink::new(
                        &s.bind.to_string(),
                        s.port,
                        options,
                    )
                    .map_err(|e| sink.error(e))?;
                    builder.set_sinks((server, file))
                }
            }
        }
    }
    .map_err(|e| sink.error(e))?;
    layout.send(&rec, APP_ID).map_err(|e| sink.error(e))?;
    rec.set_log_time_enabled(false);
    if let Sink::Serve(s) = sink {
        // Before the first frame, so a viewer can follow the run live.
        println!(
            "serving at {url}; view it live with: rerun --connect {url}",
            url = s.url()
        );
    }
    Ok(rec)
}
