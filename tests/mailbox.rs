//! The raw mailbox client (SM0/SM1 through register reads and writes) and the SDO client over it
//! (`coe/`, `pdo.rs` and others): uploads and downloads of every shape, SDO Information.

use ethercrab::SubDeviceRef;

/// Length of the drive's mailboxes (SM0 and SM1), bytes.
pub const MAILBOX_LEN: usize = 256;

/// A raw mailbox client: builds mailbox frames from the spec's byte layouts
/// and moves them through SM0/SM1 with plain register reads and writes of a
/// real master. ethercrab itself only sends expedited SDO downloads; this is
/// how the tests send segmented, normal and complete-access transfers, SDO
/// Info requests and malformed mailboxes.
pub struct RawMailbox {
    counter: u8,
    /// Send the next message with counter 0 (see [`CoeClient::hand_over`]).
    zero_next: bool,
}

impl Default for RawMailbox {
    fn default() -> Self {
        Self::new()
    }
}

impl RawMailbox {
    /// Counter starts at 1 and cycles 1..7 (ETG.1000.4 §5.6).
    pub fn new() -> Self {
        Self {
            counter: 0,
            zero_next: false,
        }
    }

    /// Sends one mailbox message (`kind` 3 = CoE, ...) and returns the
    /// response's mailbox data (after the 6-byte header) and its type, or
    /// `None` when no response arrives within 50 reads.
    pub async fn exchange<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        kind: u8,
        data: &[u8],
    ) -> Option<(u8, Vec<u8>)> {
        self.counter = if std::mem::take(&mut self.zero_next) {
            0
        } else {
            self.counter % 7 + 1
        };
        let mut frame = [0u8; MAILBOX_LEN];
        let len = data.len().min(MAILBOX_LEN - 6);
        frame[0..2].copy_from_slice(&(len as u16).to_le_bytes());
        frame[5] = (kind & 0x0F) | (self.counter << 4);
        frame[6..6 + len].copy_from_slice(&data[..len]);
        self.send_raw(sd, frame).await;
        self.receive(sd).await
    }

    /// Writes a whole, possibly malformed, SM0 buffer.
    pub async fn send_raw<S>(&mut self, sd: &SubDeviceRef<'_, S>, frame: [u8; MAILBOX_LEN]) {
        let ok = sd.register_write(0x1000u16, frame).await.is_ok();
        assert!(ok, "write SM0 mailbox");
    }

    /// Waits for SM1 to fill and reads the response.
    pub async fn receive<S>(&mut self, sd: &SubDeviceRef<'_, S>) -> Option<(u8, Vec<u8>)> {
        for _ in 0..50 {
            let status: u8 = sd.register_read(esc::regs::sm(1) + 5).await.ok()?;
            if status & esc::sm::status::MAILBOX_FULL != 0 {
                let buf: [u8; MAILBOX_LEN] = sd.register_read(0x1100u16).await.ok()?;
                let len = usize::from(u16::from_le_bytes([buf[0], buf[1]])).min(MAILBOX_LEN - 6);
                return Some((buf[5] & 0x0F, buf[6..6 + len].to_vec()));
            }
        }
        None
    }

    /// An SDO request (CoE service 2): CoE header then the 8-byte SDO part and
    /// optional extra data; returns the CoE response (header included).
    pub async fn sdo<S>(&mut self, sd: &SubDeviceRef<'_, S>, sdo: &[u8]) -> Vec<u8> {
        let mut req = vec![0x00, 0x20]; // number 0, service 2 (SDO request)
        req.extend_from_slice(sdo);
        match self.exchange(sd, 3, &req).await {
            Some((3, resp)) => resp,
            other => panic!("no CoE response: {other:?}"),
        }
    }
}

// ---------------------------------------------------------------------------
// SDO client over `RawMailbox` (tests/tests/coe/, tests/tests/pdo.rs)
// ---------------------------------------------------------------------------

/// An SDO abort code (the 32-bit CiA 301 value).
pub type Abort = u32;

/// How an upload came back.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UploadKind {
    /// Expedited (data in the initiate response, ≤ 4 bytes).
    Expedited,
    /// Normal: size indicated, all data in the initiate response.
    Normal,
    /// Segmented: size in the initiate response, data in upload segments.
    Segmented,
}

/// An entry description from SDO Info (Get Entry Description response).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EntryDesc {
    /// Value info bits supplied.
    pub value_info: u8,
    /// Data type code.
    pub data_type: u16,
    /// Bit length.
    pub bit_len: u16,
    /// Object access bits.
    pub access: u16,
    /// Default / minimum / maximum as supplied (little-endian bytes).
    pub values: Vec<Vec<u8>>,
    /// Name.
    pub name: String,
}

/// An object description from SDO Info (Get Object Description response).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ObjectDesc {
    /// Data type code of the object.
    pub data_type: u16,
    /// Highest subindex.
    pub max_sub: u8,
    /// Object code (7 VAR, 8 ARRAY, 9 RECORD).
    pub code: u8,
    /// Name.
    pub name: String,
}

/// A CoE client built on [`RawMailbox`]: SDO uploads and downloads of every
/// shape (expedited with any size, normal, segmented, complete access) and
/// SDO Information, from the spec's byte layouts (§6.2–6.4, §7).
///
/// The slave drops a request whose mailbox counter equals the previous
/// request's (duplicate detection); when ethercrab's requests are interleaved
/// that can happen by chance, so a request without reply is sent once more
/// with the next counter. Emergencies that arrive before the reply are kept in
/// [`CoeClient::emergencies`].
#[derive(Default)]
pub struct CoeClient {
    mbx: RawMailbox,
    /// EMCY payloads (8 bytes each) received while waiting for replies.
    pub emergencies: Vec<Vec<u8>>,
}

fn coe_service(resp: &[u8]) -> u8 {
    (u16::from_le_bytes([resp[0], resp[1]]) >> 12) as u8
}

impl CoeClient {
    /// A fresh client.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sends one CoE message (CoE header + service data) and returns the CoE
    /// reply (header included); panics on a mailbox error reply.
    pub async fn request<S>(&mut self, sd: &SubDeviceRef<'_, S>, coe: &[u8]) -> Vec<u8> {
        match self.try_request(sd, coe).await {
            Ok(r) => r,
            Err((kind, data)) => panic!("mailbox reply of type {kind}: {data:02x?}"),
        }
    }

    /// Like [`request`](Self::request), but a non-CoE reply (mailbox error)
    /// comes back as `Err((type, data))`.
    pub async fn try_request<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        coe: &[u8],
    ) -> Result<Vec<u8>, (u8, Vec<u8>)> {
        for _ in 0..3 {
            let mut reply = self.mbx.exchange(sd, 3, coe).await;
            loop {
                match reply {
                    Some((3, resp)) if coe_service(&resp) == 1 => {
                        self.emergencies.push(resp[2..].to_vec());
                        reply = self.mbx.receive(sd).await;
                    }
                    Some((3, resp)) => return Ok(resp),
                    Some(other) => return Err(other),
                    None => break,
                }
            }
        }
        panic!("no reply to CoE request {coe:02x?}")
    }

    /// Leaves the mailbox to another master (ethercrab) without a counter
    /// collision: one SDO upload of 1000h with counter 0, which resets the
    /// drive's repeat detection (ETG.1000.4), so whatever counter the other
    /// master sends next is new. Without it ethercrab's next request is
    /// dropped as a repeat whenever its counter equals this client's last.
    pub async fn hand_over<S>(&mut self, sd: &SubDeviceRef<'_, S>) {
        self.mbx.zero_next = true;
        let reply = self
            .request(sd, &[0x00, 0x20, 0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0])
            .await;
        assert_eq!(reply[2] >> 5, 2, "1000h upload: {reply:02x?}");
    }

    /// Sends one CoE message that gets no reply (an SDO abort request).
    pub async fn send_only<S>(&mut self, sd: &SubDeviceRef<'_, S>, coe: &[u8]) {
        let reply = self.mbx.exchange(sd, 3, coe).await;
        assert!(reply.is_none(), "unexpected reply {reply:02x?}");
    }

    /// An SDO request (8-byte SDO part + extra data); returns the SDO part of
    /// the reply (after the CoE header) or the abort code.
    pub async fn sdo<S>(&mut self, sd: &SubDeviceRef<'_, S>, sdo: &[u8]) -> Result<Vec<u8>, Abort> {
        let mut req = vec![0x00, 0x20];
        req.extend_from_slice(sdo);
        let resp = self.request(sd, &req).await;
        let body = resp[2..].to_vec();
        if body[0] == 0x80 {
            assert_eq!(coe_service(&resp), 2, "abort frames carry service 2");
            return Err(u32::from_le_bytes(body[4..8].try_into().unwrap()));
        }
        assert_eq!(coe_service(&resp), 3, "SDO response service");
        Ok(body)
    }

    /// Uploads `index`:`sub` (complete access with `ca`), following the
    /// transfer type the server chooses.
    pub async fn upload_kind<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
        sub: u8,
        ca: bool,
    ) -> Result<(Vec<u8>, UploadKind), Abort> {
        let [i0, i1] = index.to_le_bytes();
        let cmd = if ca { 0x50 } else { 0x40 };
        let r = self.sdo(sd, &[cmd, i0, i1, sub, 0, 0, 0, 0]).await?;
        assert_eq!(r[0] >> 5, 2, "scs = 2: {r:02x?}");
        assert_eq!(
            (u16::from_le_bytes([r[1], r[2]]), r[3]),
            (index, sub),
            "multiplexer echoed"
        );
        if r[0] & 0x02 != 0 {
            assert!(r[0] & 0x01 != 0, "expedited with size indicator");
            let n = 4 - usize::from((r[0] >> 2) & 3);
            return Ok((r[4..4 + n].to_vec(), UploadKind::Expedited));
        }
        assert!(r[0] & 0x01 != 0, "normal upload with size indicator");
        let size = u32::from_le_bytes(r[4..8].try_into().unwrap()) as usize;
        if r.len() > 8 || size == 0 {
            assert_eq!(
                r.len() - 8,
                size,
                "normal upload: all data in the initiate response"
            );
            return Ok((r[8..].to_vec(), UploadKind::Normal));
        }
        let mut data = Vec::new();
        let mut toggle = false;
        loop {
            let t = if toggle { 0x10 } else { 0 };
            let s = self.sdo(sd, &[0x60 | t, 0, 0, 0, 0, 0, 0, 0]).await?;
            assert_eq!(s[0] >> 5, 0, "scs = 0");
            assert_eq!(s[0] & 0x10, t, "toggle echoed");
            let unused = usize::from((s[0] >> 1) & 7);
            let seg = &s[1..];
            assert!(seg.len() >= 7, "segment of at least 7 bytes");
            data.extend_from_slice(&seg[..seg.len() - unused]);
            if s[0] & 1 != 0 {
                break;
            }
            toggle = !toggle;
        }
        assert_eq!(data.len(), size, "segmented upload delivers the announced size");
        Ok((data, UploadKind::Segmented))
    }

    /// Uploads `index`:`sub`.
    pub async fn upload<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
        sub: u8,
    ) -> Result<Vec<u8>, Abort> {
        self.upload_kind(sd, index, sub, false).await.map(|(d, _)| d)
    }

    /// Expedited download of 1..=4 bytes (command 23h/27h/2Bh/2Fh).
    pub async fn download_expedited<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), Abort> {
        assert!((1..=4).contains(&data.len()));
        let [i0, i1] = index.to_le_bytes();
        let cmd = 0x23 | (((4 - data.len()) as u8) << 2);
        let mut req = vec![cmd, i0, i1, sub, 0, 0, 0, 0];
        req[4..4 + data.len()].copy_from_slice(data);
        self.initiate_download(sd, &req).await
    }

    /// Sends the initiate download request `req` (command, index, sub, …)
    /// and checks the initiate download response (60h, index, sub).
    async fn initiate_download<S>(&mut self, sd: &SubDeviceRef<'_, S>, req: &[u8]) -> Result<(), Abort> {
        let r = self.sdo(sd, req).await?;
        assert_eq!(
            r[..4],
            [0x60, req[1], req[2], req[3]],
            "initiate download response"
        );
        Ok(())
    }

    /// The initiate download request of a normal or segmented download
    /// (command 21h, 31h with complete access) announcing `size` bytes.
    fn initiate_sized(index: u16, sub: u8, size: usize, ca: bool) -> Vec<u8> {
        let [i0, i1] = index.to_le_bytes();
        let cmd = if ca { 0x31 } else { 0x21 };
        let mut req = vec![cmd, i0, i1, sub];
        req.extend_from_slice(&(size as u32).to_le_bytes());
        req
    }

    /// Normal download with the data in the initiate request (command 21h, or
    /// 31h with complete access).
    pub async fn download_normal<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
        sub: u8,
        data: &[u8],
        ca: bool,
    ) -> Result<(), Abort> {
        let mut req = Self::initiate_sized(index, sub, data.len(), ca);
        req.extend_from_slice(data);
        self.initiate_download(sd, &req).await
    }

    /// Expedited download for 1..=4 bytes, normal otherwise.
    pub async fn download<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), Abort> {
        if (1..=4).contains(&data.len()) {
            self.download_expedited(sd, index, sub, data).await
        } else {
            self.download_normal(sd, index, sub, data, false).await
        }
    }

    /// Segmented download in CAN-style 7-byte segments (spec §6.3/§6.4):
    /// initiate 21h (31h with complete access) with the size, then segments
    /// with toggle, n and c. Returns the raw replies (SDO parts) of every step.
    pub async fn download_segmented<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
        sub: u8,
        data: &[u8],
        ca: bool,
    ) -> Result<Vec<Vec<u8>>, Abort> {
        let req = Self::initiate_sized(index, sub, data.len(), ca);
        let mut replies = vec![self.sdo(sd, &req).await?];
        let mut toggle = false;
        let chunks: Vec<&[u8]> = data.chunks(7).collect();
        for (k, chunk) in chunks.iter().enumerate() {
            let last = k + 1 == chunks.len();
            let n = (7 - chunk.len()) as u8;
            let cmd = (u8::from(toggle) << 4) | (n << 1) | u8::from(last);
            let mut seg = vec![cmd];
            seg.extend_from_slice(chunk);
            seg.resize(8, 0);
            replies.push(self.sdo(sd, &seg).await?);
            toggle = !toggle;
        }
        Ok(replies)
    }

    /// An SDO Information request (opcode + data after the 4-byte SDO Info
    /// header); returns the reply's opcode (incomplete bit cleared) and the
    /// data of all fragments joined. An SDO Info error comes back as opcode 7.
    pub async fn info<S>(&mut self, sd: &SubDeviceRef<'_, S>, opcode: u8, data: &[u8]) -> (u8, Vec<u8>) {
        let mut req = vec![0x00, 0x80, opcode, 0, 0, 0];
        req.extend_from_slice(data);
        let mut resp = self.request(sd, &req).await;
        let mut out = Vec::new();
        let mut expected_left: Option<u16> = None;
        loop {
            assert_eq!(coe_service(&resp), 8, "SDO Info service");
            let left = u16::from_le_bytes([resp[4], resp[5]]);
            if let Some(e) = expected_left {
                assert_eq!(left, e, "fragments left counts down");
            }
            assert_eq!(
                resp[2] & 0x80 != 0,
                left > 0,
                "incomplete bit while fragments follow"
            );
            out.extend_from_slice(&resp[6..]);
            if left == 0 {
                return (resp[2] & 0x7F, out);
            }
            expected_left = Some(left - 1);
            resp = match self.mbx.receive(sd).await {
                Some((3, r)) => r,
                other => panic!("missing SDO Info fragment: {other:02x?}"),
            };
        }
    }

    /// Get OD List of `list_type`: the indices.
    pub async fn od_list<S>(&mut self, sd: &SubDeviceRef<'_, S>, list_type: u16) -> Vec<u16> {
        let (op, data) = self.info(sd, 1, &list_type.to_le_bytes()).await;
        assert_eq!(op, 2, "OD list response: {data:02x?}");
        assert_eq!(u16::from_le_bytes([data[0], data[1]]), list_type);
        data[2..]
            .chunks(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]))
            .collect()
    }

    /// Get Object Description of `index`.
    pub async fn object_desc<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
    ) -> Result<ObjectDesc, Abort> {
        let (op, d) = self.info(sd, 3, &index.to_le_bytes()).await;
        if op == 7 {
            return Err(u32::from_le_bytes(d[0..4].try_into().unwrap()));
        }
        assert_eq!(op, 4);
        assert_eq!(u16::from_le_bytes([d[0], d[1]]), index);
        Ok(ObjectDesc {
            data_type: u16::from_le_bytes([d[2], d[3]]),
            max_sub: d[4],
            code: d[5],
            name: String::from_utf8_lossy(&d[6..]).into_owned(),
        })
    }

    /// Get Entry Description of `index`:`sub` asking for `value_info`;
    /// `value_size` is the byte size of each default/min/max value supplied.
    pub async fn entry_desc<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
        sub: u8,
        value_info: u8,
        value_size: usize,
    ) -> Result<EntryDesc, Abort> {
        let [i0, i1] = index.to_le_bytes();
        let (op, d) = self.info(sd, 5, &[i0, i1, sub, value_info]).await;
        if op == 7 {
            return Err(u32::from_le_bytes(d[0..4].try_into().unwrap()));
        }
        assert_eq!(op, 6);
        assert_eq!((u16::from_le_bytes([d[0], d[1]]), d[2]), (index, sub));
        let supplied = d[3];
        let mut pos = 10;
        let mut values = Vec::new();
        for bit in [0x10u8, 0x20, 0x40] {
            if supplied & bit != 0 {
                values.push(d[pos..pos + value_size].to_vec());
                pos += value_size;
            }
        }
        Ok(EntryDesc {
            value_info: supplied,
            data_type: u16::from_le_bytes([d[4], d[5]]),
            bit_len: u16::from_le_bytes([d[6], d[7]]),
            access: u16::from_le_bytes([d[8], d[9]]),
            values,
            name: String::from_utf8_lossy(&d[pos..]).into_owned(),
        })
    }
}
