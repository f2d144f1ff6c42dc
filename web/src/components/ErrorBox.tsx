import type { ApiFailure } from '../api/http';

/** The server's error envelope as the operator reads it: cause, what to do, request id. */
export function ErrorBox({ failure, title }: { failure: ApiFailure | null; title?: string }) {
  if (!failure) return null;
  const e = failure.envelope;
  return (
    <div className="error-box" role="alert">
      <strong>{title ?? 'The server refused this'}</strong>
      <p className="cause">{e.cause}</p>
      <p className="suggestion">
        <span className="label">What to do: </span>
        {e.suggestion}
      </p>
      {failure.retryAfterS !== null && <p>Try again in {failure.retryAfterS} s.</p>}
      {e.request_id && (
        <p className="request-id">
          Request id <code>{e.request_id}</code>
          {e.field ? (
            <>
              {' '}
              · field <code>{e.field}</code>
            </>
          ) : null}
        </p>
      )}
    </div>
  );
}
