// What the dashboard knows about each alert code the core raises (FailsafeMonitor, the
// server's vision supervisor): which code clears which, and what the operator should do.
// Unknown codes still show: the server's own cause and suggestion are always displayed.
import type { Severity } from '../types';

/** A "restored" alert clears the banners of the codes it names. */
export const CLEARED_BY: Readonly<Record<string, readonly string[]>> = {
  LINK_RESTORED: ['LINK_LOSS'],
  VISION_RESTORED: ['VISION_UNHEALTHY', 'VISION_WORKER_LOST'],
};

export interface AlertHelp {
  code: string;
  severity: Severity | 'varies';
  meaning: string;
  action: string;
}

export const ALERT_HELP: readonly AlertHelp[] = [
  {
    code: 'LINK_LOSS',
    severity: 'CRITICAL',
    meaning: 'No telemetry from the drone for over 2 s, or the drone reports its link lost.',
    action:
      'The drone was told to hover. Move closer or remove interference; check the adapter address. The banner clears itself when frames return (LINK_RESTORED).',
  },
  {
    code: 'LINK_RESTORED',
    severity: 'INFO',
    meaning: 'Telemetry is flowing again after a link loss.',
    action: 'Check the drone’s position on the path map before flying on.',
  },
  {
    code: 'IDLE_HOVER',
    severity: 'INFO',
    meaning: 'Flying with no gesture or key for over 3 s: the drone hovers ("Idle – hovering").',
    action: 'Show a gesture or press a flying key to continue, or land.',
  },
  {
    code: 'BATTERY_LOW',
    severity: 'WARNING',
    meaning: 'Battery under 30 %.',
    action: 'Head back and land soon.',
  },
  {
    code: 'BATTERY_CRITICAL',
    severity: 'CRITICAL',
    meaning: 'Battery under 15 %: the drone lands by itself and take-off is blocked.',
    action: 'Let it land; charge or swap the battery before the next flight.',
  },
  {
    code: 'VISION_UNHEALTHY',
    severity: 'varies',
    meaning:
      'The vision pipeline reports a problem (no camera frames, model error). Critical when flying (the drone hovers), a warning on the ground; take-off is blocked.',
    action: 'Check the camera and lighting and that your hand is in view; read the cause shown.',
  },
  {
    code: 'VISION_RESTORED',
    severity: 'INFO',
    meaning: 'Vision is healthy again; take-off is allowed again.',
    action: 'Nothing; carry on.',
  },
  {
    code: 'VISION_WORKER_LOST',
    severity: 'CRITICAL',
    meaning: 'The vision worker process crashed or went silent; the server commanded HOVER.',
    action:
      'Wait for the automatic restart (a few seconds); if it keeps failing, check the server log.',
  },
];

export interface ErrorHelp {
  error: string;
  meaning: string;
  action: string;
}

/** The server's HTTP error codes (docs/API.md). The server's cause and suggestion are shown too. */
export const ERROR_HELP: readonly ErrorHelp[] = [
  {
    error: 'invalid_credentials',
    meaning: 'Wrong e-mail or password.',
    action: 'Check both and try again; after 5 failures logins are slowed down.',
  },
  {
    error: 'weak_password',
    meaning: 'The password is under 10 characters or contains the e-mail.',
    action: 'Choose a longer password unrelated to the e-mail address.',
  },
  {
    error: 'conflict',
    meaning: 'The e-mail is already registered, or that session is already replaying.',
    action: 'Log in instead, or wait for the replay to end.',
  },
  {
    error: 'rate_limited',
    meaning: 'Too many failed logins.',
    action: 'Wait the time shown, then try again.',
  },
  {
    error: 'token_expired',
    meaning: 'Your login is older than its lifetime (at most 30 minutes).',
    action: 'Log in again.',
  },
  {
    error: 'token_revoked',
    meaning: 'You logged out (perhaps in another tab).',
    action: 'Log in again.',
  },
  { error: 'unauthorized', meaning: 'No valid login was sent.', action: 'Log in again.' },
  {
    error: 'invalid_body',
    meaning: 'A request did not match its schema (e.g. a bad mapping).',
    action: 'Fix the field named in the message and save again.',
  },
  {
    error: 'forbidden_origin',
    meaning: 'The live connection came from a page the server does not trust.',
    action:
      'Open the dashboard from the server’s own address, or add yours to GBDCS_ALLOWED_ORIGINS.',
  },
  {
    error: 'unavailable',
    meaning: 'No drone is connected.',
    action: 'Choose an adapter in Settings; check the drone is on.',
  },
  {
    error: 'internal',
    meaning: 'A server bug or storage failure.',
    action: 'Report the request id shown; the server log has the details.',
  },
];
