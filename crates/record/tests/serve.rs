//! `serve` speaks the Foxglove WebSocket protocol: a client on 127.0.0.1 is told the
//! recording's channels with their schema names, and after subscribing receives the
//! recorded messages byte for byte. (Feature `serve`; a minimal WebSocket client in std.)
#![cfg(feature = "serve")]

use clutchpack_record::synthetic::synthetic_run;
use clutchpack_record::{open, serve, RecordOptions, Recorder, ServeOptions};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};
use std::time::Duration;

/// Reads one WebSocket frame (server frames are not masked): (opcode, payload).
fn read_frame(s: &mut TcpStream) -> (u8, Vec<u8>) {
    let mut h = [0u8; 2];
    s.read_exact(&mut h).unwrap();
    let mut len = u64::from(h[1] & 0x7f);
    if len == 126 {
        let mut b = [0u8; 2];
        s.read_exact(&mut b).unwrap();
        len = u64::from(u16::from_be_bytes(b));
    } else if len == 127 {
        let mut b = [0u8; 8];
        s.read_exact(&mut b).unwrap();
        len = u64::from_be_bytes(b);
    }
    let mut payload = vec![0u8; len as usize];
    s.read_exact(&mut payload).unwrap();
    (h[0] & 0x0f, payload)
}

/// Sends one masked text frame.
fn send_text(s: &mut TcpStream, text: &str) {
    let p = text.as_bytes();
    let mut f = vec![0x81u8];
    if p.len() < 126 {
        f.push(0x80 | p.len() as u8);
    } else {
        f.push(0x80 | 126);
        f.extend_from_slice(&(p.len() as u16).to_be_bytes());
    }
    let mask = [1u8, 2, 3, 4];
    f.extend_from_slice(&mask);
    f.extend(p.iter().enumerate().map(|(i, b)| b ^ mask[i % 4]));
    s.write_all(&f).unwrap();
}

#[test]
fn serves_channels_and_messages_over_the_foxglove_protocol() {
    let run = synthetic_run(200, 1e-5);
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("clutchpack_record");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("serve.mcap");
    let mut rec = Recorder::create(&path, &run.info, &RecordOptions::default()).unwrap();
    run.play(&mut rec);
    rec.finish(None).unwrap();
    let reader = open(&path).unwrap();
    let mut first_shaft = None;
    reader.for_each_message(|m| {
        if m.topic == "/shaft" && first_shaft.is_none() {
            first_shaft = Some(m.data.to_vec());
        }
    });

    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = mpsc::channel();
    let server = {
        let stop = stop.clone();
        std::thread::spawn(move || {
            let opts = ServeOptions {
                port: 0,
                speed: 0.001,
                autoplay: true,
                ..Default::default()
            };
            serve(&reader, &opts, &stop, |port| tx.send(port).unwrap()).unwrap();
        })
    };
    let port = rx.recv_timeout(Duration::from_secs(20)).unwrap();
    let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    write!(
        s,
        "GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
         Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\
         Sec-WebSocket-Protocol: foxglove.sdk.v1\r\n\r\n"
    )
    .unwrap();
    let mut head = Vec::new();
    while !head.ends_with(b"\r\n\r\n") {
        let mut b = [0u8; 1];
        s.read_exact(&mut b).unwrap();
        head.push(b[0]);
    }
    let head = String::from_utf8_lossy(&head);
    assert!(head.starts_with("HTTP/1.1 101"), "{head}");

    // serverInfo, then advertise with our channels
    let mut shaft_id = None;
    let mut schemas = Vec::new();
    while shaft_id.is_none() {
        let (op, payload) = read_frame(&mut s);
        if op != 1 {
            continue;
        }
        let v: serde_json::Value = serde_json::from_slice(&payload).unwrap();
        if v["op"] == "advertise" {
            for c in v["channels"].as_array().unwrap() {
                schemas.push((
                    c["topic"].as_str().unwrap().to_string(),
                    c["schemaName"].as_str().unwrap().to_string(),
                ));
                if c["topic"] == "/shaft" {
                    shaft_id = c["id"].as_u64();
                }
            }
        }
    }
    assert!(
        schemas.contains(&("/tf".into(), "foxglove.FrameTransforms".into())),
        "{schemas:?}"
    );
    assert!(schemas.contains(&("/scene".into(), "foxglove.SceneUpdate".into())));

    send_text(
        &mut s,
        &format!(
            r#"{{"op":"subscribe","subscriptions":[{{"id":7,"channelId":{}}}]}}"#,
            shaft_id.unwrap()
        ),
    );
    // binary message data: opcode 0x01, subscription id u32, log time u64, payload
    let data = loop {
        let (op, payload) = read_frame(&mut s);
        if op == 2 && payload[0] == 0x01 {
            break payload;
        }
    };
    assert_eq!(u32::from_le_bytes(data[1..5].try_into().unwrap()), 7);
    let log_time = u64::from_le_bytes(data[5..13].try_into().unwrap());
    assert!(log_time <= 2_000_000, "{log_time}");
    if log_time == 0 {
        assert_eq!(Some(data[13..].to_vec()), first_shaft);
    }
    stop.store(true, Ordering::Relaxed);
    server.join().unwrap();
}
