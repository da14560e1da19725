//! `serve` speaks the Foxglove WebSocket protocol to old and new clients: a client on
//! 127.0.0.1 offering only `foxglove.websocket.v1` (Foxglove Studio <= 1.87, Lichtblick) or
//! only `foxglove.sdk.v1` (current Foxglove) is told the recording's channels with their
//! schema names and, after subscribing, receives the recorded messages byte for byte,
//! without ever sending a play request; the static pack (`/scene`, one message at t = 0) is
//! latched, so it arrives whenever a client subscribes; other subprotocols are refused with
//! a reason. (Feature `serve`; a minimal WebSocket client in std.)
#![cfg(feature = "serve")]

use clutchpack_record::synthetic::synthetic_run;
use clutchpack_record::{open, serve, RecordOptions, Recorder, RecordingReader, ServeOptions};
use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

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

/// Per topic, messages `(log time ns, bytes)`.
type ByTopic = BTreeMap<String, Vec<(u64, Vec<u8>)>>;

/// A recording of the synthetic run (200 samples 10 us apart, so 2 ms simulated) and, per
/// topic, its messages `(log time ns, bytes)` in file order.
fn recording(name: &str) -> (RecordingReader, ByTopic) {
    let run = synthetic_run(200, 1e-5);
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("clutchpack_record");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let mut rec = Recorder::create(&path, &run.info, &RecordOptions::default()).unwrap();
    run.play(&mut rec);
    rec.finish(None).unwrap();
    let reader = open(&path).unwrap();
    let mut by_topic = ByTopic::new();
    reader.for_each_message(|m| {
        by_topic
            .entry(m.topic.to_string())
            .or_default()
            .push((m.log_time_ns, m.data.to_vec()));
    });
    (reader, by_topic)
}

/// Starts `serve` on a free port in a thread: (port, stop flag, thread).
fn start(reader: RecordingReader, options: ServeOptions) -> (u16, Arc<AtomicBool>, JoinHandle<()>) {
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = mpsc::channel();
    let server = {
        let stop = stop.clone();
        std::thread::spawn(move || {
            serve(&reader, &options, &stop, |port| tx.send(port).unwrap()).unwrap();
        })
    };
    let port = rx.recv_timeout(Duration::from_secs(20)).unwrap();
    (port, stop, server)
}

/// Sends a WebSocket upgrade request offering `protocols` and returns the stream and the
/// answer's head (and for a refusal, the body too).
fn handshake(port: u16, protocols: &str) -> (TcpStream, String) {
    let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    write!(
        s,
        "GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
         Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\
         Sec-WebSocket-Protocol: {protocols}\r\n\r\n"
    )
    .unwrap();
    let mut head = Vec::new();
    while !head.ends_with(b"\r\n\r\n") {
        let mut b = [0u8; 1];
        s.read_exact(&mut b).unwrap();
        head.push(b[0]);
    }
    (s, String::from_utf8_lossy(&head).into_owned())
}

/// What a client that subscribes to every channel and never sends a play request receives
/// within `wait`: the advertised `(topic, schema)` per channel id, and per topic the
/// `(log time, bytes)` of each message; also whether a `PlaybackState` (binary op 5) came.
struct Received {
    schemas: BTreeMap<u64, (String, String)>,
    messages: ByTopic,
    playback_state: bool,
}

fn subscribe_all_and_listen(s: &mut TcpStream, until: impl Fn(&Received) -> bool) -> Received {
    let mut r = Received {
        schemas: BTreeMap::new(),
        messages: BTreeMap::new(),
        playback_state: false,
    };
    let t0 = Instant::now();
    while !until(&r) && t0.elapsed() < Duration::from_secs(30) {
        let (op, payload) = read_frame(s);
        if op == 1 {
            let v: serde_json::Value = serde_json::from_slice(&payload).unwrap();
            if v["op"] == "advertise" {
                let mut subs = Vec::new();
                for c in v["channels"].as_array().unwrap() {
                    let id = c["id"].as_u64().unwrap();
                    r.schemas.insert(
                        id,
                        (
                            c["topic"].as_str().unwrap().to_string(),
                            c["schemaName"].as_str().unwrap_or_default().to_string(),
                        ),
                    );
                    // subscription id = channel id
                    subs.push(format!(r#"{{"id":{id},"channelId":{id}}}"#));
                }
                send_text(
                    s,
                    &format!(
                        r#"{{"op":"subscribe","subscriptions":[{}]}}"#,
                        subs.join(",")
                    ),
                );
            }
        } else if op == 2 && payload.first() == Some(&0x01) {
            // message data: op 1, subscription id u32, log time u64, payload
            let sub = u64::from(u32::from_le_bytes(payload[1..5].try_into().unwrap()));
            let t = u64::from_le_bytes(payload[5..13].try_into().unwrap());
            let topic = r.schemas[&sub].0.clone();
            r.messages
                .entry(topic)
                .or_default()
                .push((t, payload[13..].to_vec()));
        } else if op == 2 && payload.first() == Some(&0x05) {
            r.playback_state = true;
        }
    }
    r
}

/// A client offering only `protocol` is accepted with it, sees our channels, and receives
/// messages without sending play: the static `/scene` (its only message, t = 0), `/summary`
/// and `/shaft` messages, each equal to one in the file at the same log time.
fn client_receives_without_play(protocol: &str, file: &str) -> Received {
    let (reader, want) = recording(file);
    let (port, stop, server) = start(
        reader,
        ServeOptions {
            port: 0,
            ..Default::default()
        },
    );
    let (mut s, head) = handshake(port, protocol);
    assert!(head.starts_with("HTTP/1.1 101"), "{head}");
    let proto_line = head
        .lines()
        .find(|l| {
            l.to_ascii_lowercase()
                .starts_with("sec-websocket-protocol:")
        })
        .unwrap_or_default()
        .to_string();
    assert!(proto_line.ends_with(&format!(" {protocol}")), "{head}");
    let done = |r: &Received| {
        ["/scene", "/summary", "/shaft"]
            .iter()
            .all(|t| r.messages.get(*t).is_some_and(|m| !m.is_empty()))
            && r.messages.get("/shaft").map_or(0, Vec::len) >= 3
    };
    let r = subscribe_all_and_listen(&mut s, done);
    stop.store(true, Ordering::Relaxed);
    server.join().unwrap();
    assert!(
        done(&r),
        "received only {:?}",
        r.messages.keys().collect::<Vec<_>>()
    );
    let schemas: Vec<&(String, String)> = r.schemas.values().collect();
    for (topic, schema) in [
        ("/tf", "foxglove.FrameTransforms"),
        ("/scene", "foxglove.SceneUpdate"),
        ("/scene/loads", "foxglove.SceneUpdate"),
        ("/shaft", "clutchpack.ShaftState"),
    ] {
        assert!(
            schemas.contains(&&(topic.to_string(), schema.to_string())),
            "{schemas:?}"
        );
    }
    for (topic, got) in &r.messages {
        for m in got {
            assert!(
                want[topic].contains(m),
                "{topic} at {} ns is not a message of the file",
                m.0
            );
        }
    }
    assert_eq!(r.messages["/scene"][0], want["/scene"][0]);
    assert_eq!(want["/scene"].len(), 1, "the static scene is one message");
    r
}

#[test]
fn a_classic_foxglove_websocket_v1_client_receives_messages_without_play() {
    let r = client_receives_without_play("foxglove.websocket.v1", "serve-classic.mcap");
    assert!(
        !r.playback_state,
        "a classic client must not get PlaybackState (op 5), which its protocol lacks"
    );
}

#[test]
fn a_foxglove_sdk_v1_client_receives_messages_without_play() {
    client_receives_without_play("foxglove.sdk.v1", "serve-sdk.mcap");
}

/// A client offering neither subprotocol is refused with HTTP 400 and a body that names what
/// it offered and the three subprotocols accepted.
#[test]
fn other_subprotocols_are_refused_with_the_reason() {
    let (reader, _) = recording("serve-refuse.mcap");
    let (port, stop, server) = start(
        reader,
        ServeOptions {
            port: 0,
            ..Default::default()
        },
    );
    let (mut s, head) = handshake(port, "chat, foxglove.sdk.v2");
    assert!(head.starts_with("HTTP/1.1 400"), "{head}");
    let mut body = String::new();
    s.read_to_string(&mut body).unwrap();
    assert!(body.contains("offered: chat, foxglove.sdk.v2"), "{body}");
    for p in [
        "foxglove.sdk.v1.1",
        "foxglove.sdk.v1",
        "foxglove.websocket.v1",
    ] {
        assert!(body.contains(p), "{body}");
    }
    stop.store(true, Ordering::Relaxed);
    server.join().unwrap();
}

/// With `autoplay: false` nothing plays before a play request, but a subscriber still gets
/// the latched state at the start: the static `/scene` and `/summary` (both at t = 0).
#[test]
fn paused_server_still_latches_the_static_scene() {
    let (reader, want) = recording("serve-paused.mcap");
    let (port, stop, server) = start(
        reader,
        ServeOptions {
            port: 0,
            autoplay: false,
            ..Default::default()
        },
    );
    let (mut s, head) = handshake(port, "foxglove.sdk.v1");
    assert!(head.starts_with("HTTP/1.1 101"), "{head}");
    let done =
        |r: &Received| r.messages.contains_key("/scene") && r.messages.contains_key("/summary");
    let r = subscribe_all_and_listen(&mut s, done);
    stop.store(true, Ordering::Relaxed);
    server.join().unwrap();
    assert!(done(&r), "{:?}", r.messages.keys().collect::<Vec<_>>());
    assert_eq!(r.messages["/scene"][0], want["/scene"][0]);
    // only latched messages at t = 0: playback did not start
    assert!(r.messages.values().flatten().all(|m| m.0 == 0));
}
