//! `replay --serve`: plays a recording to Foxglove over its WebSocket protocol (feature
//! `serve`, which pulls in tokio through the `foxglove` SDK's server).
//!
//! The server listens on [`ServeOptions::host`] (127.0.0.1 by default) and declares the
//! recording's time range, so Foxglove shows its playback bar: play, pause, seek and speed
//! are honoured. Messages are sent in log-time order at `speed` times simulated time (the
//! simulated seconds of a clutch run are short: 0.01 plays 1 s of simulation in 100 s).

use crate::read::RecordingReader;
use foxglove::websocket::{
    Capability, PlaybackCommand, PlaybackControlRequest, PlaybackState, PlaybackStatus,
    ServerListener,
};
use foxglove::{Context, RawChannel, Schema, WebSocketServer};
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How [`serve`] plays a recording.
#[derive(Debug, Clone, PartialEq)]
pub struct ServeOptions {
    /// Address to listen on. Default `127.0.0.1` (this machine only).
    pub host: String,
    /// TCP port; 0 picks a free one. Default 8765 (Foxglove's default).
    pub port: u16,
    /// Playback speed as a factor of simulated time. Default 0.01.
    pub speed: f32,
    /// Start playing at once (otherwise wait for the viewer's play button). Default `false`.
    pub autoplay: bool,
}

impl Default for ServeOptions {
    fn default() -> Self {
        ServeOptions {
            host: "127.0.0.1".into(),
            port: 8765,
            speed: 0.01,
            autoplay: false,
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
    next: usize,
    status: PlaybackStatus,
    speed: f32,
    /// simulated time (ns) that plays at wall instant `anchor_wall`
    anchor_ns: u64,
    anchor_wall: Instant,
    start_ns: u64,
    end_ns: u64,
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

struct Listener(Arc<Mutex<Player>>);

impl ServerListener for Listener {
    fn on_playback_control_request(&self, r: PlaybackControlRequest) -> Option<PlaybackState> {
        let mut p = self.0.lock().ok()?;
        let now = p.current_ns();
        p.set_anchor(now);
        if r.playback_speed.is_finite() && r.playback_speed > 0.0 {
            p.speed = r.playback_speed;
        }
        let mut did_seek = false;
        if let Some(t) = r.seek_time {
            let t = t.clamp(p.start_ns, p.end_ns);
            p.next = p.messages.partition_point(|m| m.0 < t);
            p.set_anchor(t);
            did_seek = true;
        }
        p.status = match r.playback_command {
            PlaybackCommand::Play if p.next < p.messages.len() => PlaybackStatus::Playing,
            PlaybackCommand::Play => PlaybackStatus::Ended,
            PlaybackCommand::Pause => PlaybackStatus::Paused,
        };
        Some(p.state(did_seek, Some(r.request_id)))
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
    messages.sort_by_key(|m| m.0);
    let start_ns = messages.first().map_or(0, |m| m.0);
    let end_ns = messages.last().map_or(0, |m| m.0).max(start_ns + 1);
    let player = Arc::new(Mutex::new(Player {
        messages,
        next: 0,
        status: if options.autoplay {
            PlaybackStatus::Playing
        } else {
            PlaybackStatus::Paused
        },
        speed: if options.speed > 0.0 {
            options.speed
        } else {
            1.0
        },
        anchor_ns: start_ns,
        anchor_wall: Instant::now(),
        start_ns,
        end_ns,
    }));
    let name = reader
        .path()
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "recording".into());
    let server = WebSocketServer::new()
        .name(name)
        .context(&ctx)
        .capabilities([Capability::Time])
        .playback_time_range(start_ns, end_ns)
        .listener(Arc::new(Listener(player.clone())))
        .bind(options.host.clone(), options.port)
        .start_blocking()
        .map_err(|e| ServeError::Start {
            host: options.host.clone(),
            port: options.port,
            reason: e.to_string(),
        })?;
    on_ready(server.port());
    let mut last_status = PlaybackStatus::Paused;
    while !stop.load(Ordering::Relaxed) {
        let mut sleep = Duration::from_millis(10);
        if let Ok(mut p) = player.lock() {
            if p.status == PlaybackStatus::Playing {
                let now = p.current_ns();
                while p.next < p.messages.len() && p.messages[p.next].0 <= now {
                    let (t, ch, data) = &p.messages[p.next];
                    channels[*ch]
                        .log_with_meta(data, foxglove::PartialMetadata { log_time: Some(*t) });
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
