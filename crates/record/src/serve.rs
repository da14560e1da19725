//! `replay --serve`: plays a recording to Foxglove, Lichtblick and other clients of the
//! Foxglove WebSocket protocol (feature `serve`, which pulls in tokio through the `foxglove`
//! SDK's server).
//!
//! **Subprotocols.** The `foxglove` SDK's server negotiates only `foxglove.sdk.v1` and
//! `foxglove.sdk.v1.1` (current Foxglove), and answers anything else with HTTP 400; its
//! handshake has no option for more. Foxglove Studio up to 1.87 and Lichtblick offer the
//! classic `foxglove.websocket.v1`, whose messages the SDK's `foxglove.sdk.v1` shares (the
//! SDK added ops, it did not change any). So [`serve`] listens itself and hands each
//! connection to the SDK server on an internal loopback port:
//! - a client offering `foxglove.sdk.v1.1` or `foxglove.sdk.v1` is passed through as it is;
//! - a client offering only `foxglove.websocket.v1` is passed through with its handshake
//!   renamed to `foxglove.sdk.v1` and the answer renamed back, and the server's
//!   `PlaybackState` messages (binary op 5, which the classic protocol does not have) are
//!   left out of its stream;
//! - anything else gets HTTP 400 naming the subprotocols offered and the three accepted.
//!
//! **Playback.** The server declares the recording's time range, so Foxglove shows its
//! playback bar: play, pause, seek and speed are honoured. By default playback starts when
//! the first client subscribes (a client without playback control receives the messages
//! too), and starts again from the beginning when a new client subscribes after the end;
//! [`ServeOptions::autoplay`] `false` waits for a play request instead. Messages are sent in
//! log-time order at `speed` times simulated time (the simulated seconds of a clutch run are
//! short: 0.01 plays 1 s of simulation in 100 s).
//!
//! **Latched state.** A client that subscribes to a channel at once receives that channel's
//! latest message at or before the current playback time, and after a seek every subscribed
//! channel's latest message at or before the seek time is sent again: so the static pack
//! (`/scene`, one message at t = 0), the load colours and `/summary` are there at any time,
//! as when a viewer opens the file itself.

use crate::read::RecordingReader;
use foxglove::websocket::{
    Capability, ChannelView, Client, ClientId, PlaybackCommand, PlaybackControlRequest,
    PlaybackState, PlaybackStatus, ServerListener,
};
use foxglove::{Context, PartialMetadata, RawChannel, Schema, WebSocketServer};
use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The subprotocols [`serve`] accepts, newest first.
pub const SUBPROTOCOLS: [&str; 3] = [SDK_V1_1, SDK_V1, CLASSIC_V1];
const SDK_V1_1: &str = "foxglove.sdk.v1.1";
const SDK_V1: &str = "foxglove.sdk.v1";
const CLASSIC_V1: &str = "foxglove.websocket.v1";

/// How [`serve`] plays a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct ServeOptions {
    /// Address to listen on. Default `127.0.0.1` (this machine only).
    pub host: String,
    /// TCP port; 0 picks a free one. Default 8765 (Foxglove's default).
    pub port: u16,
    /// Playback speed as a factor of simulated time. Default 0.01.
    pub speed: f32,
    /// Start playing when the first client subscribes (and again from the start when a new
    /// client subscribes after the end); `false` waits for a client's play request.
    /// Default `true`.
    pub autoplay: bool,
}

impl Default for ServeOptions {
    fn default() -> Self {
        ServeOptions {
            host: "127.0.0.1".into(),
            port: 8765,
            speed: 0.01,
            autoplay: true,
        }
    }
}

/// Why a recording could not be served.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// The server could not start (port in use, bad address).
    #[error("cannot start the Foxglove WebSocket server on {host}:{port}: {reason}")]
    Start {
        /// Host.
        host: String,
        /// Port.
        port: u16,
        /// The SDK's error.
        reason: String,
    },
    /// A channel could not be created.
    #[error("cannot create the channel {topic}: {reason}")]
    Channel {
        /// Topic.
        topic: String,
        /// The SDK's error.
        reason: String,
    },
}

struct Player {
    /// (log time ns, channel index, data), sorted by log time
    messages: Vec<(u64, usize, Vec<u8>)>,
    /// per channel, the indices of its messages in `messages` (ascending)
    by_channel: Vec<Vec<usize>>,
    next: usize,
    status: PlaybackStatus,
    speed: f32,
    /// simulated time (ns) that plays at wall instant `anchor_wall`
    anchor_ns: u64,
    anchor_wall: Instant,
    start_ns: u64,
    end_ns: u64,
    autoplay: bool,
    /// clients that have subscribed to something
    clients: Vec<ClientId>,
    /// a seek happened: re-send the latest message of each channel at the next tick
    backfill: bool,
}

impl Player {
    fn current_ns(&self) -> u64 {
        match self.status {
            PlaybackStatus::Playing => {
                let dt = self.anchor_wall.elapsed().as_secs_f64() * f64::from(self.speed);
                (self.anchor_ns + (dt * 1e9) as u64).min(self.end_ns)
            }
            _ => self.anchor_ns,
        }
    }

    fn set_anchor(&mut self, ns: u64) {
        self.anchor_ns = ns;
        self.anchor_wall = Instant::now();
    }

    fn seek(&mut self, t: u64) {
        let t = t.clamp(self.start_ns, self.end_ns);
        self.next = self.messages.partition_point(|m| m.0 <= t);
        self.set_anchor(t);
        self.backfill = true;
    }

    /// The index in `messages` of channel `ch`'s latest message at or before `t` (ns).
    fn latest(&self, ch: usize, t: u64) -> Option<usize> {
        let idx = self.by_channel.get(ch)?;
        let k = idx.partition_point(|&i| self.messages[i].0 <= t);
        k.checked_sub(1).map(|k| idx[k])
    }

    fn state(&self, did_seek: bool, request_id: Option<String>) -> PlaybackState {
        PlaybackState {
            status: self.status,
            current_time: self.current_ns(),
            playback_speed: self.speed,
            did_seek,
            request_id,
        }
    }
}

struct Listener {
    player: Arc<Mutex<Player>>,
    channels: Arc<Vec<Arc<RawChannel>>>,
    /// our channel index by the SDK's channel id
    index: BTreeMap<u64, usize>,
}

impl ServerListener for Listener {
    fn on_playback_control_request(&self, r: PlaybackControlRequest) -> Option<PlaybackState> {
        let mut p = self.player.lock().ok()?;
        let now = p.current_ns();
        p.set_anchor(now);
        if r.playback_speed.is_finite() && r.playback_speed > 0.0 {
            p.speed = r.playback_speed;
        }
        let mut did_seek = false;
        if let Some(t) = r.seek_time {
            p.seek(t);
            did_seek = true;
        }
        p.status = match r.playback_command {
            PlaybackCommand::Play if p.next < p.messages.len() => PlaybackStatus::Playing,
            PlaybackCommand::Play => PlaybackStatus::Ended,
            PlaybackCommand::Pause => PlaybackStatus::Paused,
        };
        Some(p.state(did_seek, Some(r.request_id)))
    }

    /// Latches: the new subscriber gets the channel's latest message at or before the
    /// playback time at once; with autoplay, the first subscriber (or a new one after the end)
    /// starts playback from the beginning.
    fn on_subscribe(&self, client: Client, channel: ChannelView) {
        let Some(&ch) = self.index.get(&u64::from(channel.id())) else {
            return;
        };
        let Ok(mut p) = self.player.lock() else {
            return;
        };
        let new_client = !p.clients.contains(&client.id());
        if new_client {
            p.clients.push(client.id());
        }
        let idle = p.status == PlaybackStatus::Ended
            || (p.clients.len() == 1 && p.status == PlaybackStatus::Paused && p.next == 0);
        if p.autoplay && new_client && idle {
            let start = p.start_ns;
            p.seek(start);
            p.backfill = false;
            p.next = 0;
            p.status = PlaybackStatus::Playing;
            // playback sends everything from the start, this channel's first message too
            return;
        }
        let now = p.current_ns();
        // while playing, only what playback has passed (the rest comes with it, in order)
        let playing = p.status == PlaybackStatus::Playing;
        if let Some(i) = p.latest(ch, now).filter(|&i| !playing || i < p.next) {
            let (t, _, data) = &p.messages[i];
            if let Some(c) = self.channels.get(ch) {
                c.log_with_meta_to_sink(
                    data,
                    PartialMetadata { log_time: Some(*t) },
                    client.sink_id(),
                );
            }
        }
    }
}

/// Serves `reader` until `stop` becomes true, calling `on_ready` with the bound port once the
/// server listens. Blocks; set `stop` from a Ctrl-C handler. The whole recording is held in
/// memory, decoded no further than its MCAP records.
pub fn serve(
    reader: &RecordingReader,
    options: &ServeOptions,
    stop: &AtomicBool,
    on_ready: impl FnOnce(u16),
) -> Result<(), ServeError> {
    let ctx = Context::new();
    let mut channels: Vec<Arc<RawChannel>> = Vec::new();
    let mut index: BTreeMap<u16, usize> = BTreeMap::new();
    let mut messages = Vec::new();
    let mut err = None;
    reader.for_each_message(|m| {
        if err.is_some() {
            return;
        }
        let i = match index.get(&m.channel_id) {
            Some(&i) => i,
            None => {
                let schema = (!m.schema_name.is_empty())
                    .then(|| Schema::new(m.schema_name, m.schema_encoding, m.schema_data.to_vec()));
                match ctx
                    .channel_builder(m.topic)
                    .message_encoding(m.message_encoding)
                    .schema(schema)
                    .build_raw()
                {
                    Ok(c) => {
                        channels.push(c);
                        index.insert(m.channel_id, channels.len() - 1);
                        channels.len() - 1
                    }
                    Err(e) => {
                        err = Some(ServeError::Channel {
                            topic: m.topic.to_string(),
                            reason: e.to_string(),
                        });
                        return;
                    }
                }
            }
        };
        messages.push((m.log_time_ns, i, m.data.to_vec()));
    });
    if let Some(e) = err {
        return Err(e);
    }
    // stable: messages of equal log time keep their file order
    messages.sort_by_key(|m| m.0);
    let mut by_channel = vec![Vec::new(); channels.len()];
    for (k, m) in messages.iter().enumerate() {
        by_channel[m.1].push(k);
    }
    let start_ns = messages.first().map_or(0, |m| m.0);
    let end_ns = messages.last().map_or(0, |m| m.0).max(start_ns + 1);
    let player = Arc::new(Mutex::new(Player {
        messages,
        by_channel,
        next: 0,
        status: PlaybackStatus::Paused,
        speed: if options.speed > 0.0 {
            options.speed
        } else {
            1.0
        },
        anchor_ns: start_ns,
        anchor_wall: Instant::now(),
        start_ns,
        end_ns,
        autoplay: options.autoplay,
        clients: Vec::new(),
        backfill: false,
    }));
    let channels = Arc::new(channels);
    let listener = Listener {
        player: player.clone(),
        channels: channels.clone(),
        index: channels
            .iter()
            .enumerate()
            .map(|(i, c)| (u64::from(c.id()), i))
            .collect(),
    };
    let name = reader
        .path()
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "recording".into());
    let start_err = |reason: String| ServeError::Start {
        host: options.host.clone(),
        port: options.port,
        reason,
    };
    // the front door: every client connects here and is handed to the SDK server
    let front = TcpListener::bind((options.host.as_str(), options.port))
        .map_err(|e| start_err(e.to_string()))?;
    front
        .set_nonblocking(true)
        .map_err(|e| start_err(e.to_string()))?;
    let port = front
        .local_addr()
        .map_err(|e| start_err(e.to_string()))?
        .port();
    let server = WebSocketServer::new()
        .name(name)
        .context(&ctx)
        .capabilities([Capability::Time])
        .playback_time_range(start_ns, end_ns)
        .listener(Arc::new(listener))
        .bind("127.0.0.1", 0)
        .start_blocking()
        .map_err(|e| start_err(e.to_string()))?;
    let inner_port = server.port();
    on_ready(port);
    let mut last_status = PlaybackStatus::Paused;
    while !stop.load(Ordering::Relaxed) {
        let mut sleep = Duration::from_millis(10);
        while let Ok((stream, _)) = front.accept() {
            std::thread::spawn(move || hand_over(stream, inner_port));
        }
        if let Ok(mut p) = player.lock() {
            if p.backfill {
                p.backfill = false;
                let now = p.current_ns();
                for (ch, c) in channels.iter().enumerate() {
                    if let Some(i) = p.latest(ch, now) {
                        let (t, _, data) = &p.messages[i];
                        c.log_with_meta(data, PartialMetadata { log_time: Some(*t) });
                    }
                }
            }
            if p.status == PlaybackStatus::Playing {
                let now = p.current_ns();
                while p.next < p.messages.len() && p.messages[p.next].0 <= now {
                    let (t, ch, data) = &p.messages[p.next];
                    channels[*ch].log_with_meta(data, PartialMetadata { log_time: Some(*t) });
                    p.next += 1;
                }
                server.broadcast_time(now);
                if p.next >= p.messages.len() {
                    p.status = PlaybackStatus::Ended;
                    p.set_anchor(end_ns);
                } else {
                    sleep = Duration::from_millis(5);
                }
            }
            if p.status != last_status {
                server.broadcast_playback_state(p.state(false, None));
                last_status = p.status;
            }
        }
        std::thread::sleep(sleep);
    }
    server.stop().wait_blocking();
    Ok(())
}

/// What to do with a client's WebSocket handshake.
#[derive(Debug, PartialEq)]
enum Handshake {
    /// It offers a subprotocol of the SDK's: pass it on unchanged.
    Pass,
    /// It offers only the classic subprotocol: rename it both ways.
    Classic,
    /// Refuse with HTTP 400 and this reason.
    Refuse(String),
}

/// Decides on a request head (request line and headers, without the blank line).
fn judge(head: &str) -> Handshake {
    let mut offered = Vec::new();
    for line in head.lines().skip(1) {
        if let Some((k, v)) = line.split_once(':') {
            if k.trim().eq_ignore_ascii_case("sec-websocket-protocol") {
                offered.extend(v.split(',').map(|p| p.trim().to_string()));
            }
        }
    }
    let has = |p: &str| offered.iter().any(|o| o == p);
    if has(SDK_V1_1) || has(SDK_V1) {
        Handshake::Pass
    } else if has(CLASSIC_V1) {
        Handshake::Classic
    } else {
        let offered = if offered.is_empty() {
            "none (no Sec-WebSocket-Protocol header)".to_string()
        } else {
            offered.join(", ")
        };
        Handshake::Refuse(format!(
            "clutchpack replay --serve speaks the Foxglove WebSocket protocol: offer one of \
             the subprotocols {} (offered: {offered})",
            SUBPROTOCOLS.join(", ")
        ))
    }
}

/// Reads an HTTP head up to and including its blank line: (head text without the blank line,
/// bytes read past it).
fn read_head(s: &mut TcpStream) -> Option<(String, Vec<u8>)> {
    let mut buf = Vec::with_capacity(1024);
    let mut chunk = [0u8; 2048];
    loop {
        if let Some(end) = buf.windows(4).position(|w| w == b"\r\n\r\n") {
            let rest = buf.split_off(end + 4);
            buf.truncate(end);
            return Some((String::from_utf8_lossy(&buf).into_owned(), rest));
        }
        if buf.len() > 64 * 1024 {
            return None;
        }
        let n = s.read(&mut chunk).ok()?;
        if n == 0 {
            return None;
        }
        buf.extend_from_slice(&chunk[..n]);
    }
}

/// The head with every `Sec-WebSocket-Protocol` header replaced by one naming `protocol`.
fn with_protocol(head: &str, protocol: &str) -> String {
    let mut out = String::with_capacity(head.len() + 64);
    for line in head.split("\r\n") {
        let is_protocol = line
            .split_once(':')
            .is_some_and(|(k, _)| k.trim().eq_ignore_ascii_case("sec-websocket-protocol"));
        if !is_protocol {
            out.push_str(line);
            out.push_str("\r\n");
        }
    }
    out.push_str("Sec-WebSocket-Protocol: ");
    out.push_str(protocol);
    out.push_str("\r\n\r\n");
    out
}

/// Serves one client connection: judges its handshake and connects it to the SDK server on
/// `inner_port` (see the module documentation).
fn hand_over(mut client: TcpStream, inner_port: u16) {
    let _ = client.set_nonblocking(false);
    let _ = client.set_read_timeout(Some(Duration::from_secs(10)));
    let Some((head, rest)) = read_head(&mut client) else {
        return;
    };
    let mode = judge(&head);
    if let Handshake::Refuse(reason) = &mode {
        let _ = write!(
            client,
            "HTTP/1.1 400 Bad Request\r\nContent-Type: text/plain; charset=utf-8\r\n\
             Content-Length: {}\r\nConnection: close\r\n\r\n{reason}",
            reason.len()
        );
        return;
    }
    let Ok(mut upstream) = TcpStream::connect(("127.0.0.1", inner_port)) else {
        return;
    };
    let head = match mode {
        Handshake::Classic => with_protocol(&head, SDK_V1),
        _ => format!("{head}\r\n\r\n"),
    };
    if upstream.write_all(head.as_bytes()).is_err() || upstream.write_all(&rest).is_err() {
        return;
    }
    let _ = client.set_read_timeout(None);
    if mode == Handshake::Classic {
        let _ = upstream.set_read_timeout(Some(Duration::from_secs(10)));
        let Some((answer, rest)) = read_head(&mut upstream) else {
            return;
        };
        let _ = upstream.set_read_timeout(None);
        let answer = if answer.starts_with("HTTP/1.1 101") {
            with_protocol(&answer, CLASSIC_V1)
        } else {
            format!("{answer}\r\n\r\n")
        };
        if client.write_all(answer.as_bytes()).is_err() {
            return;
        }
        let (Ok(c2), Ok(u2)) = (client.try_clone(), upstream.try_clone()) else {
            return;
        };
        let down = std::thread::spawn(move || {
            let mut rest = std::io::Cursor::new(rest).chain(u2);
            copy_frames_without_playback_state(&mut rest, &mut { c2 });
        });
        copy(&mut client, &mut upstream);
        let _ = down.join();
    } else {
        let (Ok(mut c2), Ok(mut u2)) = (client.try_clone(), upstream.try_clone()) else {
            return;
        };
        let down = std::thread::spawn(move || copy(&mut u2, &mut c2));
        copy(&mut client, &mut upstream);
        let _ = down.join();
    }
}

/// Copies `from` to `to` until either ends, then shuts both down (so the other direction
/// ends too).
fn copy(from: &mut TcpStream, to: &mut TcpStream) {
    let _ = std::io::copy(from, to);
    let _ = from.shutdown(Shutdown::Both);
    let _ = to.shutdown(Shutdown::Both);
}

/// Copies the server's WebSocket frames to a classic client, leaving out binary messages
/// whose first byte is op 5 (`PlaybackState`, not in `foxglove.websocket.v1`) with their
/// continuation frames. RFC 6455 section 5.2 framing: FIN and opcode, a 7-bit length (126:
/// 16-bit follows, 127: 64-bit follows), an optional mask key, the payload.
fn copy_frames_without_playback_state(from: &mut impl Read, to: &mut TcpStream) {
    let mut dropping = false;
    loop {
        let mut h = [0u8; 2];
        if from.read_exact(&mut h).is_err() {
            break;
        }
        let mut header = h.to_vec();
        let (fin, opcode) = (h[0] & 0x80 != 0, h[0] & 0x0f);
        let mut len = u64::from(h[1] & 0x7f);
        if len == 126 {
            let mut b = [0u8; 2];
            if from.read_exact(&mut b).is_err() {
                break;
            }
            header.extend_from_slice(&b);
            len = u64::from(u16::from_be_bytes(b));
        } else if len == 127 {
            let mut b = [0u8; 8];
            if from.read_exact(&mut b).is_err() {
                break;
            }
            header.extend_from_slice(&b);
            len = u64::from_be_bytes(b);
        }
        if h[1] & 0x80 != 0 {
            let mut m = [0u8; 4];
            if from.read_exact(&mut m).is_err() {
                break;
            }
            header.extend_from_slice(&m);
        }
        let mut payload = Vec::new();
        if from.take(len).read_to_end(&mut payload).is_err() || payload.len() as u64 != len {
            break;
        }
        let drop = match opcode {
            // a binary message starts with its op
            2 => payload.first() == Some(&5),
            // a continuation belongs to the message before it
            0 => dropping,
            _ => false,
        };
        if opcode == 0 || opcode == 2 {
            dropping = drop && !fin;
        }
        if !drop && (to.write_all(&header).is_err() || to.write_all(&payload).is_err()) {
            break;
        }
    }
    let _ = to.shutdown(Shutdown::Both);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The handshake is judged on the offered subprotocols, names exact, case and spaces of
    /// the header as clients send them.
    #[test]
    fn handshakes_are_judged_by_subprotocol() {
        let req = |p: &str| format!("GET / HTTP/1.1\r\nHost: x\r\n{p}");
        assert_eq!(
            judge(&req("Sec-WebSocket-Protocol: foxglove.sdk.v1")),
            Handshake::Pass
        );
        assert_eq!(
            judge(&req(
                "sec-websocket-protocol: foxglove.websocket.v1, foxglove.sdk.v1.1"
            )),
            Handshake::Pass
        );
        assert_eq!(
            judge(&req("Sec-WebSocket-Protocol: foxglove.websocket.v1")),
            Handshake::Classic
        );
        let Handshake::Refuse(r) = judge(&req("Sec-WebSocket-Protocol: foxglove.sdk.v2, chat"))
        else {
            panic!("refused")
        };
        assert!(r.contains("offered: foxglove.sdk.v2, chat"), "{r}");
        assert!(r.contains(CLASSIC_V1) && r.contains(SDK_V1_1), "{r}");
        let Handshake::Refuse(r) = judge(&req("Upgrade: websocket")) else {
            panic!("refused")
        };
        assert!(r.contains("no Sec-WebSocket-Protocol header"), "{r}");
    }

    /// Renaming the subprotocol keeps every other header line and the blank line.
    #[test]
    fn protocol_header_is_replaced() {
        let head = "HTTP/1.1 101 Switching Protocols\r\nsec-websocket-protocol: foxglove.sdk.v1\r\nUpgrade: websocket";
        assert_eq!(
            with_protocol(head, CLASSIC_V1),
            "HTTP/1.1 101 Switching Protocols\r\nUpgrade: websocket\r\n\
             Sec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n"
        );
    }
}
