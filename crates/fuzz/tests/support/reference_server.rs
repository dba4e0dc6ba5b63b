//! The reference drive served on a loopback TCP port in wall-clock time, a fresh drive for
//! every connection (each connection in its own thread, for `limit` at most).

use drivespec_hpd::model::{Drive, DriveConfig, Output};
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::time::{Duration, Instant};

/// Starts the server; returns its port. It stops accepting after `limit`.
pub fn start(limit: Duration) -> u16 {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    let proto = Drive::new(
        drivespec_implementations::spec(),
        DriveConfig::commissioned(0),
    )
    .unwrap();
    std::thread::spawn(move || {
        listener.set_nonblocking(true).unwrap();
        let started = Instant::now();
        while started.elapsed() < limit {
            match listener.accept() {
                Ok((s, _)) => {
                    let drive = proto.clone();
                    let left = limit.saturating_sub(started.elapsed());
                    std::thread::spawn(move || serve(s, drive, left));
                }
                Err(_) => std::thread::sleep(Duration::from_millis(1)),
            }
        }
    });
    port
}

fn serve(mut s: TcpStream, mut drive: Drive, limit: Duration) {
    s.set_nonblocking(false).unwrap();
    s.set_nodelay(true).unwrap();
    s.set_read_timeout(Some(Duration::from_micros(300)))
        .unwrap();
    let start = Instant::now();
    let now = || start.elapsed().as_micros() as u64;
    let mut buf = [0u8; 256];
    while start.elapsed() < limit {
        match s.read(&mut buf) {
            Ok(0) => return,
            Ok(n) => drive.handle_rx(now(), &buf[..n]),
            Err(_) => {}
        }
        drive.advance(now());
        while let Some(o) = drive.poll_output() {
            if let Output::Transmit { bytes, .. } = o {
                if s.write_all(&bytes).is_err() {
                    return;
                }
            }
        }
    }
}
