//! The client/server transport of the hybrid scheme over TCP (paper 03, Fig. 1): the client
//! asks once for the static package and then for one dynamic package per ROI.
//!
//! Requests: a magic byte `0xD3`, then the operation (u8): 1 static package, 2 ROI package
//! followed by the ROI's min and max (6 x u32, little-endian), 3 close. Replies: a status
//! (u8: 0 ok, 1 error), a length (u64) and that many bytes: the package, or a UTF-8 error
//! message. Replies are capped at [`MAX_REPLY`] bytes on the client side.

use std::io::{BufReader, BufWriter, Read, Write};
use std::net::{TcpListener, TcpStream, ToSocketAddrs};
use std::sync::Arc;

use wscg_math::{Error, Result};

use crate::package::HybridServer;

const REQUEST_MAGIC: u8 = 0xD3;
const OP_STATIC: u8 = 1;
const OP_ROI: u8 = 2;
const OP_CLOSE: u8 = 3;
/// Largest reply a client accepts (4 GiB).
pub const MAX_REPLY: u64 = 1 << 32;

fn io(e: std::io::Error) -> Error {
    Error::invalid("network", e.to_string())
}

fn reply(w: &mut impl Write, ok: bool, body: &[u8]) -> std::io::Result<()> {
    w.write_all(&[u8::from(!ok)])?;
    w.write_all(&(body.len() as u64).to_le_bytes())?;
    w.write_all(body)?;
    w.flush()
}

/// Serves one connection until the client closes it or sends a malformed request.
pub fn serve_connection(server: &HybridServer, stream: TcpStream) -> Result<()> {
    let mut r = BufReader::new(stream.try_clone().map_err(io)?);
    let mut w = BufWriter::new(stream);
    let static_pkg = std::sync::OnceLock::new();
    loop {
        let mut head = [0u8; 2];
        match r.read_exact(&mut head) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(()),
            Err(e) => return Err(io(e)),
        }
        if head[0] != REQUEST_MAGIC {
            reply(&mut w, false, b"bad request magic").map_err(io)?;
            return Err(Error::invalid("network", "bad request magic"));
        }
        match head[1] {
            OP_STATIC => {
                let pkg: &Vec<u8> = static_pkg.get_or_init(|| server.static_package());
                reply(&mut w, true, pkg).map_err(io)?;
            }
            OP_ROI => {
                let mut b = [0u8; 24];
                r.read_exact(&mut b).map_err(io)?;
                let v: Vec<u32> = b
                    .chunks_exact(4)
                    .map(|c| u32::from_le_bytes(c.try_into().expect("4")))
                    .collect();
                match server.roi_package([v[0], v[1], v[2]], [v[3], v[4], v[5]]) {
                    Ok(pkg) => reply(&mut w, true, &pkg).map_err(io)?,
                    Err(e) => reply(&mut w, false, e.to_string().as_bytes()).map_err(io)?,
                }
            }
            OP_CLOSE => return Ok(()),
            op => {
                reply(&mut w, false, format!("unknown operation {op}").as_bytes()).map_err(io)?;
                return Err(Error::invalid("network", format!("unknown operation {op}")));
            }
        }
    }
}

/// Accepts connections on `listener` and serves each on its own thread; returns after
/// `max_connections` connections (`None`: never).
pub fn serve(
    server: Arc<HybridServer>,
    listener: TcpListener,
    max_connections: Option<usize>,
) -> Result<()> {
    let mut handles = Vec::new();
    for (k, stream) in listener.incoming().enumerate() {
        let stream = stream.map_err(io)?;
        let s = Arc::clone(&server);
        handles.push(std::thread::spawn(move || serve_connection(&s, stream)));
        if max_connections.is_some_and(|m| k + 1 >= m) {
            break;
        }
    }
    for h in handles {
        h.join()
            .map_err(|_| Error::Numerical("a connection thread panicked".into()))??;
    }
    Ok(())
}

/// A connection to a hybrid server.
pub struct RemoteServer {
    stream: TcpStream,
}

impl RemoteServer {
    /// Connects to `addr`.
    pub fn connect(addr: impl ToSocketAddrs) -> Result<Self> {
        Ok(Self {
            stream: TcpStream::connect(addr).map_err(io)?,
        })
    }

    fn request(&mut self, op: u8, args: &[u32]) -> Result<Vec<u8>> {
        let mut req = vec![REQUEST_MAGIC, op];
        args.iter()
            .for_each(|a| req.extend_from_slice(&a.to_le_bytes()));
        self.stream.write_all(&req).map_err(io)?;
        let mut head = [0u8; 9];
        self.stream.read_exact(&mut head).map_err(io)?;
        let len = u64::from_le_bytes(head[1..9].try_into().expect("8"));
        if len > MAX_REPLY {
            return Err(Error::invalid("network", format!("reply of {len} bytes")));
        }
        let mut body = Vec::new();
        (&mut self.stream)
            .take(len)
            .read_to_end(&mut body)
            .map_err(io)?;
        if body.len() as u64 != len {
            return Err(Error::invalid("network", "connection closed mid-reply"));
        }
        match head[0] {
            0 => Ok(body),
            _ => Err(Error::invalid(
                "server",
                String::from_utf8_lossy(&body).into_owned(),
            )),
        }
    }

    /// The static package.
    pub fn static_package(&mut self) -> Result<Vec<u8>> {
        self.request(OP_STATIC, &[])
    }

    /// The dynamic package of the ROI `[min, max)`.
    pub fn roi_package(&mut self, min: [u32; 3], max: [u32; 3]) -> Result<Vec<u8>> {
        self.request(OP_ROI, &[min[0], min[1], min[2], max[0], max[1], max[2]])
    }

    /// Closes the connection.
    pub fn close(mut self) -> Result<()> {
        self.stream
            .write_all(&[REQUEST_MAGIC, OP_CLOSE])
            .map_err(io)
    }
}
